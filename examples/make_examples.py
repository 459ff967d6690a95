# Writes the example drawings (SVG) and project files under examples/ (python3 make_examples.py).
# The SVGs are the source of truth for the lead and the tests; this only records how they were drawn.
import json, math, os
ROOT = os.path.dirname(os.path.abspath(__file__))

def f(v):
    s = ('%.1f' % v).rstrip('0').rstrip('.')
    return '0' if s in ('-0', '') else s

def pts(ps):
    return ' '.join('%s,%s' % (f(x), f(y)) for x, y in ps)

def svg(w, h, title, body):
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" viewBox="0 0 %d %d">\n'
            '  <title>%s</title>\n%s</svg>\n') % (w, h, w, h, title, body)

def write(name, files, project_extra=None, drawings=None):
    d = os.path.join(ROOT, name)
    os.makedirs(d, exist_ok=True)
    for fname, text in files:
        assert len(text) < 5000, (name, fname, len(text))
        open(os.path.join(d, fname), 'w').write(text)
    proj = {'version': 1, 'drawings': drawings or [fn for fn, _ in files],
            'inbetween': {'frames': 24}}
    if project_extra:
        for k, v in project_extra.items():
            proj.setdefault(k, {}).update(v) if isinstance(v, dict) else proj.__setitem__(k, v)
    open(os.path.join(d, 'project.json'), 'w').write(json.dumps(proj, indent=2) + '\n')

# --- existing examples get project files
write('square_hexagon', [], drawings=['square.svg', 'hexagon.svg'])
write('bar_arch', [], drawings=['bar.svg', 'arch.svg'])

# --- pentagon -> star, six difficulty levels (S-Table 4): inner radius 0.7 .. 0.2 of the outer
for level in range(1, 7):
    ratio = 0.8 - 0.1 * level
    c, R = 60, 50
    pent = [(c + R * math.cos(math.radians(-90 + 72 * k)), c + R * math.sin(math.radians(-90 + 72 * k))) for k in range(5)]
    star = []
    for k in range(10):
        r = R if k % 2 == 0 else R * ratio
        a = math.radians(-90 + 36 * k)
        star.append((c + r * math.cos(a), c + r * math.sin(a)))
    write('pentagon_star/hard%d' % level, [
        ('pentagon.svg', svg(120, 120, 'Key drawing 1: regular pentagon, circumradius 50',
                             '  <polygon id="pentagon" fill="#5a8fd0" points="%s"/>\n' % pts(pent))),
        ('star.svg', svg(120, 120, 'Key drawing 2: five-pointed star, inner radius %.1f x outer' % ratio,
                         '  <polygon id="star" fill="#e0a030" points="%s"/>\n' % pts(star))),
    ])

# --- limbs: a limb leaves a body edge at `top` in direction angle a (degrees from +y, towards +x),
def unit(a):
    return (math.sin(math.radians(a)), math.cos(math.radians(a)))

def add(p, q, s=1.0):
    return (p[0] + s * q[0], p[1] + s * q[1])

def intersect(p, d, q, e):
    # p + s d = q + t e
    den = d[0] * e[1] - d[1] * e[0]
    s = ((q[0] - p[0]) * e[1] - (q[1] - p[1]) * e[0]) / den
    return add(p, d, s)

# --- walking character, a whole walk cycle in 16 keys (two steps: contact, down, passing, up).
#     Side-view silhouette: head, torso, one arm, two legs. Where a limb lies across the body the
#     silhouette alone loses it, so a cut draws its edge inside the body: the legs in the passing
#     poses (one strip, cut down the middle) and the arm while it swings back across the torso
#     (a cut along its hand end and inner edge). Marks: 1 the crotch (the tip of the legs'
#     cut when they pass), 2 the armpit (the tip of the arm's cut when it lies on the torso), 3 the
#     front hip.
ARM_W, ARM_L = 7, 34

def walker(front, back, arm, passing=False, geo=None):
    # geo (a dict, optional) receives the arm's frame for the layered walk below: shoulder T,
    # direction d, inner-edge normal n, hand, corner, and 'armpit' or 'x'/'tip'.
    P = (0, -6); w = 9; L = 54
    out = []
    cuts = []
    marks = {}
    # head (arc) and neck, walked clockwise on screen from the back of the neck
    head = 'M -3 -66 A 11 11 0 1 1 5 -66'
    out_pts = [(5, -62), (9, -60)]
    d = unit(arm); n = (-math.cos(math.radians(arm)), math.sin(math.radians(arm)))
    T = (9, -60)
    hand = add(T, d, ARM_L)
    corner = add(add(hand, n, ARM_W), d, 2)
    marks[8] = hand
    marks[10] = (1, -66 - math.sqrt(105) - 11)  # the top of the head
    if geo is not None:
        geo.update(T=T, d=d, n=n, hand=hand, corner=corner)
    if corner[0] > 9:
        # arm held in front of the torso (x = 9): the armpit where its inner edge meets the front
        armpit = intersect(add(T, n, ARM_W), d, T, (0, 1))
        out_pts += [hand, corner, armpit]
        marks[2] = armpit
        if geo is not None:
            geo['armpit'] = armpit
        marks[13] = corner
    else:
        # arm hanging over the torso front: only the hand shows past the front; the arm's hand
        # end and inner edge are a cut from where the hand meets the front up to below the
        # shoulder (the arm stays attached there)
        x = intersect(hand, add(corner, hand, -1), T, (0, 1))
        tip = add(add(T, n, ARM_W), d, 6)
        out_pts += [hand, x]
        cuts.append([x, corner, tip])
        marks[2] = tip
        if geo is not None:
            geo.update(x=x, tip=tip)
        marks[13] = corner  # on the cut: the arm's side is the first on the boundary
    out_pts += [(9, -10)]
    legs_from = len(out_pts) - 1
    marks[3] = (9, -10)  # where the torso front meets the front leg
    def leg_edges(a):
        d = unit(a); n = (math.cos(math.radians(a)), -math.sin(math.radians(a)))
        fr = add(P, n, w / 2); bk = add(P, n, -w / 2)
        return d, n, fr, bk
    df, nf, ff, fb = leg_edges(front)
    db, nb, bf, bb = leg_edges(back)
    toe = lambda e, d, n: add(add(e, n, 8), d, 2)
    if passing:
        # legs side by side, each as wide as in the other keys: the front leg planted, the back
        # one lifted a little; a cut between them up to the crotch
        out_pts += [(9, 48), (17, 50), (0, 50), (0, 46), (-9, 46)]
        cuts.append([(0, 46), (0, 2)])
        marks[1] = (0, 2)
        marks[6] = (17, 50)  # front toe
        marks[7] = (-9, 46)  # back heel
    else:
        crotch = intersect(fb, df, bf, db)
        ef, eb = add(ff, df, L), add(fb, df, L)
        out_pts += [ff, ef, toe(ef, df, nf), add(eb, df, 2), eb, crotch]
        marks.update({1: crotch, 6: toe(ef, df, nf), 11: ff, 14: ef, 15: add(eb, df, 2), 16: eb})
        ef, eb = add(bf, db, L), add(bb, db, L)
        out_pts += [ef, toe(ef, db, nb), add(eb, db, 2), eb, bb]
        marks.update({7: eb, 9: toe(ef, db, nb), 12: bb, 17: ef, 18: add(eb, db, 2)})
    out_pts += [(-9, -10), (-10, -56), (-3, -62)]
    if geo is not None:
        geo['legs'] = out_pts[legs_from:-2]  # the outline from the front hip round to the back one
    marks[4] = (-9, -10)  # where the back leg meets the torso
    marks[5] = (9, -60)  # the shoulder
    dpath = head + ' L ' + ' L '.join('%s %s' % (f(x), f(y)) for x, y in out_pts) + ' Z'
    return dpath, cuts, marks

# (name, front leg, back leg, arm, body bob): legs in degrees from straight down, arm likewise
# (below about 11 the arm hangs over the torso front), bob in y (down is positive)
step = [('contact', 28, -28, 0), ('down', 25, -27, 3), ('rise', 21, -21, 1), ('lift', 17, -17, 0),
        ('passing', 14, -14, -1), ('up', 17, -16, -3), ('reach', 21, -20, -2), ('fall', 25, -24, -1)]
arms = [48, 44, 40, 36, 32, 28, 4, 4, 4, 4, 28, 32, 36, 40, 44, 48]
files = []
for i in range(16):
    name, fr, bk, bob = step[i % 8]
    dpath, cuts, marks = walker(fr, bk, arms[i])
    body = '  <g transform="translate(40 %s)">\n' % f(96 + bob)
    body += '    <path id="walker" fill="#3a3a48" d="%s"/>\n' % dpath
    for c in cuts:
        body += '    <path class="cut" d="M %s" stroke="red" fill="none"/>\n' % ' L '.join('%s %s' % (f(x), f(y)) for x, y in c)
    for k in sorted(marks):
        body += '    <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (k, f(marks[k][0]), f(marks[k][1]))
    body += '  </g>\n'
    files.append(('%02d_%s.svg' % (i + 1, name),
                  svg(100, 160, 'Walk cycle key %d of 16: %s, arm at %d degrees (side view silhouette)' % (i + 1, name, arms[i]), body)))
write('walk', files, {'inbetween': {'timing': 'catmull_rom', 'frames': 91},
                      'meshing': {'boundary_vertices': 560, 'max_edge_relative': 0.016}})

# --- flying bird: the wing folded onto the body (a cut) opens up and away
def bird(wing_tip1, wing_tip2, folded):
    body = 'M 100 52 Q 96 42 86 42 L 76 44'
    if folded:
        body += ' L 12 44'
    else:
        body += ' L %s %s L %s %s L 62 44 L 12 44' % (f(wing_tip1[0]), f(wing_tip1[1]), f(wing_tip2[0]), f(wing_tip2[1]))
    body += ' L 2 36 L 6 50 Q 30 70 70 64 Q 90 60 100 52 Z'
    return body
bird_files = []
for i, (name, t1, t2) in enumerate([('folded', None, None), ('raised', (30, 20), (24, 26)), ('up', (44, 2), (38, 6))]):
    b = '  <path id="bird" fill="#2f6f8f" d="%s"/>\n' % bird(t1, t2, name == 'folded')
    if name == 'folded':
        b += '  <path class="cut" d="M 36 38 L 62 50" stroke="red" fill="none"/>\n'
        b += '  <circle data-corr="1" cx="62" cy="50" r="1" fill="red"/>\n'
    else:
        b += '  <circle data-corr="1" cx="62" cy="44" r="1" fill="red"/>\n'
    bird_files.append(('%d_%s.svg' % (i + 1, name), svg(110, 80, 'Flying bird key %d: wing %s' % (i + 1, name), b)))
write('bird', bird_files)

# --- closed mouth that opens: disk -> annulus through an opening
face = 'M 10 50 A 40 40 0 1 1 90 50 A 40 40 0 1 1 10 50 Z'
write('mouth', [
    ('1_closed.svg', svg(100, 100, 'Mouth key 1: closed (an opening marks the lips)',
                         '  <path id="face" fill="#e8b040" d="%s"/>\n'
                         '  <path class="opening" d="M 30 58 Q 50 68 70 58" stroke="red" fill="none"/>\n' % face)),
    ('2_ajar.svg', svg(100, 100, 'Mouth key 2: ajar',
                       '  <path id="face" fill="#e8b040" fill-rule="evenodd"\n        d="%s M 30 58 Q 50 62 70 58 Q 50 76 30 58 Z"/>\n' % face)),
    ('3_open.svg', svg(100, 100, 'Mouth key 3: wide open',
                       '  <path id="face" fill="#e8b040" fill-rule="evenodd"\n        d="%s M 30 54 Q 50 56 70 54 Q 50 92 30 54 Z"/>\n' % face)),
])

# --- one shape that splits into two (a cut)
write('split', [
    ('1_whole.svg', svg(120, 100, 'Split key 1: one cell, the cut marks where it divides',
                        '  <path id="cell" fill="#6aa84f" d="M 30 30 H 90 A 20 20 0 0 1 90 70 H 30 A 20 20 0 0 1 30 30 Z"/>\n'
                        '  <path class="cut" d="M 60 20 L 60 80" stroke="red" fill="none"/>\n')),
    ('2_two.svg', svg(120, 100, 'Split key 2: two cells',
                      '  <path id="cells" fill="#6aa84f" d="M 4 50 A 22 22 0 1 1 48 50 A 22 22 0 1 1 4 50 Z M 72 50 A 22 22 0 1 1 116 50 A 22 22 0 1 1 72 50 Z"/>\n')),
])

# --- 12 principles
def ellipse(cx, cy, rx, ry, color='#d04a4a', id='ball'):
    return '  <ellipse id="%s" fill="%s" cx="%s" cy="%s" rx="%s" ry="%s"/>\n' % (id, color, f(cx), f(cy), f(rx), f(ry))
write('principles_squash_stretch', [
    ('1_round.svg', svg(100, 120, 'Squash and stretch key 1: ball at the top', ellipse(50, 24, 20, 20))),
    ('2_stretch.svg', svg(100, 120, 'Squash and stretch key 2: stretched as it falls', ellipse(50, 66, 14, 29))),
    ('3_squash.svg', svg(100, 120, 'Squash and stretch key 3: squashed on the ground', ellipse(50, 106, 30, 12))),
])
bean = 'M 0 0 C -22 0 -24 -30 -16 -52 C -10 -70 10 -70 16 -52 C 24 -30 22 0 0 0 Z'
def bean_svg(title, tf):
    return svg(120, 110, title, '  <path id="bean" fill="#8e5ac8" transform="%s"\n        d="%s"/>\n' % (tf, bean))
write('principles_anticipation', [
    ('1_stand.svg', bean_svg('Anticipation key 1: standing', 'translate(50 100)')),
    ('2_windup.svg', bean_svg('Anticipation key 2: crouched and leaning back', 'translate(46 100) skewX(14) scale(1.15 0.75)')),
    ('3_action.svg', bean_svg('Anticipation key 3: leaping forward', 'translate(74 96) skewX(-24) scale(0.85 1.25)')),
])
write('principles_slow_in_out', [
    ('1_start.svg', svg(200, 80, 'Slow in and slow out key 1: at rest on the left',
                        '  <rect id="box" fill="#4a90a0" x="10" y="20" width="40" height="40" rx="6"/>\n')),
    ('2_end.svg', svg(200, 80, 'Slow in and slow out key 2: at rest on the right, a quarter turn later',
                      '  <rect id="box" fill="#4a90a0" x="-20" y="-20" width="40" height="40" rx="6" transform="translate(170 40) rotate(90)"/>\n')),
], {'inbetween': {'timing': 'ease_in_out', 'ease': [0.8]}})
arc_files = []
for i, a in enumerate([180, 120, 60, 0]):
    cx, cy = 100 + 80 * math.cos(math.radians(a)), 100 - 80 * math.sin(math.radians(a))
    arc_files.append(('%d_ball.svg' % (i + 1), svg(200, 120, 'Arcs key %d: the ball on its arc (%d degrees)' % (i + 1, a),
                      '  <circle id="ball" fill="#d07030" cx="%s" cy="%s" r="12"/>\n' % (f(cx), f(cy)))))
write('principles_arcs', arc_files, {'inbetween': {'timing': 'catmull_rom'}})

# Follow-through and overlapping action: a block with tails (limbs) on its back edge.
def tail_pts(x0, ty, phi, length, w):
    d = (-math.cos(math.radians(phi)), -math.sin(math.radians(phi)))
    n = (-math.sin(math.radians(phi)), math.cos(math.radians(phi)))
    T = (x0, ty)
    root2 = (x0, ty + w / math.cos(math.radians(phi)))
    return [root2, add(add(T, n, w), d, length), add(T, d, length), T]

def block(x, tails):
    x0 = x - 16
    p = [(x0, 0)]
    for ty, phi, length, w in sorted(tails, reverse=True):
        p += tail_pts(x0, ty, phi, length, w)
    return ('M ' + ' L '.join('%s %s' % (f(a), f(b)) for a, b in p) +
            ' L %s -46 Q %s -58 %s -46 L %s 0 Z' % (f(x0), f(x), f(x + 16), f(x + 16)))

def block_svg(title, x, tails, color):
    return svg(170, 100, title, '  <path id="body" fill="%s" transform="translate(0 90)"\n        d="%s"/>\n' % (color, block(x, tails)))

write('principles_follow_through', [
    ('1_moving.svg', block_svg('Follow-through key 1: moving right, the tail trails', 60, [(-38, 12, 40, 7)], '#c05050')),
    ('2_stop.svg', block_svg('Follow-through key 2: stopped, the tail swings on and up', 130, [(-38, 70, 40, 7)], '#c05050')),
    ('3_settle.svg', block_svg('Follow-through key 3: the tail settles down', 130, [(-38, -40, 40, 7)], '#c05050')),
])
write('principles_overlapping_action', [
    ('1_moving.svg', block_svg('Overlapping action key 1: both strands trail', 60, [(-42, 22, 26, 6), (-20, -4, 38, 6)], '#508050')),
    ('2_stop.svg', block_svg('Overlapping action key 2: the short strand leads, the long one lags', 130, [(-42, 62, 26, 6), (-20, 12, 38, 6)], '#508050')),
    ('3_settle.svg', block_svg('Overlapping action key 3: the short strand settles first', 130, [(-42, -12, 26, 6), (-20, -32, 38, 6)], '#508050')),
    ('4_rest.svg', block_svg('Overlapping action key 4: both at rest', 130, [(-42, -20, 26, 6), (-20, -46, 38, 6)], '#508050')),
])

# Timing: a bouncing ball whose keys are spaced in time as a falling ball is (fall time ~ sqrt of
# the height): the long first fall takes most of the frames, the lower hop fewer. The key times
# are the principle; the ball moves on at a steady pace across (x follows the key time).
def bounce_key(t, cy):
    return '  <circle id="ball" fill="#3070c0" cx="%s" cy="%s" r="12"/>\n' % (f(20 + 160 * t), f(cy))
ground, top1, hop = 96, 24, 32  # ball centre on the ground, at the drop, and height of the second hop
fall1, fall2 = math.sqrt(ground - top1), math.sqrt(hop)
k = [0, fall1, fall1 + fall2, fall1 + 2 * fall2]
k = [round(v / k[-1], 2) for v in k]
timing_keys = [('1_drop.svg', 'Timing key 1: the ball dropped from high (key time 0)', top1),
               ('2_bounce.svg', 'Timing key 2: first bounce at key time %s: the long fall takes most of the frames' % k[1], ground),
               ('3_hop.svg', 'Timing key 3: top of a lower hop at key time %s: a shorter hop, fewer frames' % k[2], ground - hop),
               ('4_land.svg', 'Timing key 4: lands again (key time 1)', ground)]
write('principles_timing',
      [(fn, svg(200, 120, title, bounce_key(t, cy))) for (fn, title, cy), t in zip(timing_keys, k)],
      drawings=[{'file': fn, 'key_time': t} for (fn, _, _), t in zip(timing_keys, k)])

# Exaggeration: the squash and stretch ball pushed far beyond a natural squash (area kept). Marks
# every 22.5 degrees of the ellipse's parameter keep the arc-length correspondence from sliding
# round the ends, which would fold the ball into a diamond between the stretch and the splat.
def exaggerated(cx, cy, rx, ry):
    b = ellipse(cx, cy, rx, ry, '#c8408a')
    for i in range(16):
        a = math.radians(22.5 * i)
        b += '  <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (i + 1, f(cx + rx * math.cos(a)), f(cy - ry * math.sin(a)))
    return b
write('principles_exaggeration', [
    ('1_round.svg', svg(140, 120, 'Exaggeration key 1: ball at the top', exaggerated(70, 24, 20, 20))),
    ('2_stretch.svg', svg(140, 120, 'Exaggeration key 2: stretched to twice its height as it falls', exaggerated(70, 62, 10, 40))),
    ('3_splat.svg', svg(140, 120, 'Exaggeration key 3: splatted flat on the ground, five times its width', exaggerated(70, 110, 50, 8))),
])

# Secondary action: the block character walks right (the primary action: steps and a bob) while
# it waves hello, a motion of its own that the walk does not cause (unlike follow-through). The
# arm is a tail of block() on its front edge: the drawing is block() mirrored.
def waver_svg(title, x, bob, arm):
    return svg(190, 100, title, '  <path id="body" fill="#d08a30" transform="translate(190 %s) scale(-1 1)"\n        d="%s"/>\n'
               % (f(90 + bob), block(190 - x, [(-40, arm, 28, 6)])))
write('principles_secondary_action', [
    ('1_wave_up.svg', waver_svg('Secondary action key 1: walking right, the hand waves up', 35, 0, 60)),
    ('2_wave_out.svg', waver_svg('Secondary action key 2: a step on, the hand waves out', 65, -4, 22)),
    ('3_wave_up.svg', waver_svg('Secondary action key 3: another step, the hand up again', 95, 0, 60)),
    ('4_wave_out.svg', waver_svg('Secondary action key 4: last step, the hand out again', 125, -4, 22)),
])

# Staging: a figure shows us a ball. Held in front of its chest the ball is lost in the
# silhouette (only a bump); held out at arm's length, then up and away from the body, the action
# reads in silhouette alone. The arm leaves the front edge (x = 76) at angle a (degrees up from
# +x) and ends in the ball; marks: the neck, the arm's (or the bump's) ends on the body, the far
# side of the ball and the feet.
def holder(a, length, r=10):
    d = (math.cos(math.radians(a)), -math.sin(math.radians(a)))
    n = (-d[1], d[0])  # d turned a quarter clockwise on screen
    A = (76, 80)
    C = add(A, d, length)
    if length <= r:  # the ball on the body edge: its part beyond x = 76
        h = math.sqrt(r * r - (76 - C[0]) ** 2)
        ends = [(76, C[1] - h), (76, C[1] + h)]
        p = [ends[0]]
    else:
        w = 4
        root = [(76, A[1] - w / math.cos(math.radians(a))), (76, A[1] + w / math.cos(math.radians(a)))]
        c = math.sqrt(r * r - w * w)
        ends = [add(add(C, d, -c), n, -w), add(add(C, d, -c), n, w)]
        p = [root[0], ends[0]]
    a0 = math.atan2(ends[0][1] - C[1], ends[0][0] - C[0])
    a1 = math.atan2(ends[1][1] - C[1], ends[1][0] - C[0])
    while a1 < a0:
        a1 += 2 * math.pi
    k = 16
    p += [(C[0] + r * math.cos(a0 + (a1 - a0) * i / k), C[1] + r * math.sin(a0 + (a1 - a0) * i / k)) for i in range(1, k)]
    p += [ends[1]] + ([] if length <= r else [root[1]])
    marks = [(76, 60), p[0], add(C, d, r), p[-1], (76, 120), (40, 120)]
    dpath = 'M 40 120 L 40 60 A 20 20 0 1 1 76 60 L ' + ' L '.join('%s %s' % (f(x), f(y)) for x, y in p) + ' L 76 120 Z'
    return ('  <path id="figure" fill="#407a68" d="%s"/>\n' % dpath +
            ''.join('  <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (i + 1, f(x), f(y)) for i, (x, y) in enumerate(marks)))
write('principles_staging', [
    ('1_hidden.svg', svg(150, 125, 'Staging key 1: the ball held in front of the chest is lost in the silhouette', holder(0, 4))),
    ('2_out.svg', svg(150, 125, 'Staging key 2: the arm brings the ball out to the side, clear of the body', holder(5, 34))),
    ('3_shown.svg', svg(150, 125, 'Staging key 3: the ball held up and away: the action reads in silhouette alone', holder(40, 38))),
], {'meshing': {'boundary_vertices': 120, 'max_edge_relative': 0.1}})

# Straight ahead action (and pose to pose): a flame flickers, a motion drawn straight ahead, each
# key drawn on from the one before with no pose planned ahead (the other principles examples are
# pose to pose: extremes first, then the inbetweens). The outline is a closed Catmull-Rom spline
# through the points (smooth tips, no spikes): base, left side, left tongue, notch, main tip,
# notch, right tongue, right side.
def flame_path(tip, left, right, notches=((48, 66), (70, 62))):
    p = [(60, 112), (38, 100), (32, 80), left, notches[0], tip, notches[1], right, (88, 82), (82, 100)]
    n = len(p)
    d = 'M %s %s' % (f(p[0][0]), f(p[0][1]))
    for i in range(n):
        a, b, c, e = p[i - 1], p[i], p[(i + 1) % n], p[(i + 2) % n]
        c1 = (b[0] + (c[0] - a[0]) / 6, b[1] + (c[1] - a[1]) / 6)
        c2 = (c[0] - (e[0] - b[0]) / 6, c[1] - (e[1] - b[1]) / 6)
        d += ' C %s %s %s %s %s %s' % (f(c1[0]), f(c1[1]), f(c2[0]), f(c2[1]), f(c[0]), f(c[1]))
    return '  <path id="flame" fill="#e8762a" d="%s Z"/>\n' % d
write('principles_straight_ahead_pose_to_pose', [
    ('1_flame.svg', svg(120, 120, 'Straight ahead key 1: the flame as first drawn',
                        flame_path((58, 14), (36, 50), (84, 42)))),
    ('2_flame.svg', svg(120, 120, 'Straight ahead key 2: drawn on from key 1: the tip licks left, the right tongue rises',
                        flame_path((44, 20), (34, 56), (88, 32), ((46, 70), (68, 58))))),
    ('3_flame.svg', svg(120, 120, 'Straight ahead key 3: drawn on from key 2: the tip leaps up and right, the left tongue rises',
                        flame_path((70, 6), (30, 40), (86, 52), ((50, 62), (74, 66))))),
    ('4_flame.svg', svg(120, 120, 'Straight ahead key 4: drawn on from key 3: the flame sinks and leans left',
                        flame_path((50, 22), (32, 48), (82, 46), ((46, 66), (66, 64))))),
], {'meshing': {'boundary_vertices': 120, 'max_edge_relative': 0.1}})

# Solid drawing: an open box (a cube without its lid, seen from 35 degrees above) turns about
# its vertical axis; its outline and its opening (a hole: the top face inset by the wall
# thickness) foreshorten together as a solid's would. For turns between 0 and 90 degrees the
# outline is always the same six corners of the cube (the left, back and right ones of the top,
# the right, front and left ones of the foot) and the opening the four inset ones: all ten are
# marks, so corners map to corners and turn instead of being rounded off between the keys.
def box_corners(psi, half, y, elev=35):
    e = math.radians(elev)
    out = []
    for a in (135, 225, 315, 45):  # left, back, right, front at psi = 0 (x right, z towards us)
        t = math.radians(a + psi)
        x, z = half * math.sqrt(2) * math.cos(t), half * math.sqrt(2) * math.sin(t)
        out.append((70 + x, 92 - (y * math.cos(e) - z * math.sin(e))))
    return out

def open_box(psi, side=56, wall=6):
    bottom, top = box_corners(psi, side / 2, 0), box_corners(psi, side / 2, side)
    inner = box_corners(psi, side / 2 - wall, side)
    outline = [bottom[0], top[0], top[1], top[2], bottom[2], bottom[3]]
    d = 'M ' + ' L '.join('%s %s' % (f(x), f(y)) for x, y in outline) + ' Z'
    d += ' M ' + ' L '.join('%s %s' % (f(x), f(y)) for x, y in inner) + ' Z'
    b = '  <path id="box" fill="#7a6a58" fill-rule="evenodd" d="%s"/>\n' % d
    for i, p in enumerate(outline + inner):
        b += '  <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (i + 1, f(p[0]), f(p[1]))
    return b
write('principles_solid_drawing', [
    ('1_turn15.svg', svg(140, 120, 'Solid drawing key 1: an open box, turned 15 degrees', open_box(15))),
    ('2_turn45.svg', svg(140, 120, 'Solid drawing key 2: turned 45 degrees, corner on', open_box(45))),
    ('3_turn75.svg', svg(140, 120, 'Solid drawing key 3: turned 75 degrees', open_box(75))),
])

# Appeal: the same face redesigned to charm: from a long head with small eyes set high and a flat
# mouth to a round head, big eyes set lower and a wide smile, with a tilt. One path, the eyes and
# the mouth its holes; marks 1 and 2 are the corners of the mouth.
def oval(cx, cy, rx, ry):
    return 'M %s %s A %s %s 0 1 0 %s %s A %s %s 0 1 0 %s %s Z' % (
        f(cx - rx), f(cy), f(rx), f(ry), f(cx + rx), f(cy), f(rx), f(ry), f(cx - rx), f(cy))

def face_svg(title, head, eye, eye_dx, eye_y, mouth, tilt=0):
    (l, y), (r, _) = mouth[0], mouth[1]
    d = oval(60, 60, *head) + ' ' + oval(60 - eye_dx, eye_y, *eye) + ' ' + oval(60 + eye_dx, eye_y, *eye)
    d += ' M %s %s Q 60 %s %s %s Q 60 %s %s %s Z' % (f(l), f(y), f(mouth[2]), f(r), f(y), f(mouth[3]), f(l), f(y))
    b = '  <g transform="rotate(%s 60 60)">\n' % f(tilt)
    b += '    <path id="face" fill="#e0a070" fill-rule="evenodd" d="%s"/>\n' % d
    b += ''.join('    <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (i + 1, f(x), f(y)) for i, x in enumerate((l, r)))
    return svg(120, 110, title, b + '  </g>\n')
write('principles_appeal', [
    ('1_plain.svg', face_svg('Appeal key 1: a plain face: long head, small eyes set high, a flat mouth',
                             (30, 42), (4, 4.5), 14, 44, ((50, 80), (70, 80), 78, 86))),
    ('2_rounder.svg', face_svg('Appeal key 2: a rounder head, bigger eyes set lower, the mouth starts to smile',
                               (36, 38), (7, 8.5), 14, 54, ((46, 80), (74, 80), 83, 92))),
    ('3_appealing.svg', face_svg('Appeal key 3: round head, big eyes, a wide smile and a tilt of the head',
                                 (38, 36), (8.5, 10.5), 15, 56, ((42, 77), (78, 77), 84, 100), -6)),
], {'meshing': {'boundary_vertices': 120, 'max_edge_relative': 0.1}})

# --- Layered art: drawings as an artist paints them, fills and line work over each other
#     (docs/svg-convention.md). The silhouette is the union of the paint (or the class="outline"
#     element); the layers ride the mesh and morph into the layer of the same data-layer name in
#     the next key. Paint that lies along a cut is drawn a little off it, on the side it belongs to:
#     a point on the cut would ride whichever side the mesh finds first and could stay behind when
#     the cut opens.
INK = '#2b2233'

def layer(tag, name, paint, **geom):
    attrs = ' '.join('%s="%s"' % (k.replace('_', '-'), v) for k, v in geom.items())
    return '  <%s data-layer="%s" %s %s/>\n' % (tag, name, attrs, paint)

def stroke(width, color=INK):
    return 'fill="none" stroke="%s" stroke-width="%s" stroke-linecap="round" stroke-linejoin="round"' % (
        color, f(width))

def polyline_d(ps, closed=False):
    return 'M ' + ' L '.join('%s %s' % (f(x), f(y)) for x, y in ps) + (' Z' if closed else '')

# A face changing expression: head with an outline stroke, hair, eyes (white and pupil), brows,
# nose and mouth, each its own layer; the smile adds blushing cheeks (a layer only that key has:
# it cross-fades in and out). The silhouette is the head: everything else is painted on it.
def face_key(title, head, brows, eyes, pupil_r, mouth, blush=False):
    cx, cy, rx, ry = head
    b = layer('ellipse', 'head', 'fill="#f2c79b" stroke="%s" stroke-width="2.5"' % INK,
              cx=f(cx), cy=f(cy), rx=f(rx), ry=f(ry))
    # hair: the head's outline from 200 to 340 degrees, a fringe back across the forehead
    p = lambda a: (cx + rx * math.cos(math.radians(a)), cy + ry * math.sin(math.radians(a)))
    (x0, y0), (x1, y1) = p(200), p(340)
    top = cy - ry
    b += layer('path', 'hair', 'fill="#6b4226"', d='M %s %s A %s %s 0 0 1 %s %s Q %s %s %s %s Q %s %s %s %s Z' % (
        f(x0), f(y0), f(rx), f(ry), f(x1), f(y1), f(cx + 18), f(top + 10), f(cx + 2), f(top + 16),
        f(cx - 16), f(top + 12), f(x0), f(y0)))
    if blush:
        for side in (-1, 1):
            b += layer('ellipse', 'cheek', 'fill="#e8707a" opacity="0.45"', cx=f(cx + side * 24),
                       cy=f(cy + 12), rx='7', ry='4.5')
    ex, ey, erx, ery = eyes
    for side, name in ((-1, 'left'), (1, 'right')):
        b += layer('ellipse', name + '-eye', 'fill="#ffffff" stroke="%s" stroke-width="1.2"' % INK,
                   cx=f(cx + side * ex), cy=f(ey), rx=f(erx), ry=f(ery))
        b += layer('circle', name + '-pupil', 'fill="%s"' % INK, cx=f(cx + side * ex + 1), cy=f(ey + 1),
                   r=f(pupil_r))
    for side, name in ((-1, 'left'), (1, 'right')):
        (ax, ay), (qx, qy), (zx, zy) = brows
        b += layer('path', name + '-brow', stroke(3), d='M %s %s Q %s %s %s %s' % (
            f(cx + side * ax), f(ay), f(cx + side * qx), f(qy), f(cx + side * zx), f(zy)))
    b += layer('path', 'nose', stroke(1.5), d='M %s %s Q %s %s %s %s' % (
        f(cx), f(cy + 2), f(cx - 5), f(cy + 12), f(cx + 2), f(cy + 14)))
    (l, my), (r, _), upper, lower = mouth
    b += layer('path', 'mouth', 'fill="#8a2b2b" stroke="%s" stroke-width="1.5" stroke-linejoin="round"' % INK,
               d='M %s %s Q %s %s %s %s Q %s %s %s %s Z' % (f(l), f(my), f(cx), f(upper), f(r), f(my),
                                                          f(cx), f(lower), f(l), f(my)))
    return svg(120, 120, title, b)
write('layered_face', [
    ('1_neutral.svg', face_key('Layered face key 1: neutral', (60, 62, 40, 44),
                               ((8, 41), (16, 39), (25, 42)), (16, 55, 7, 7.5), 3.5,
                               ((50, 86), (70, 86), 87, 90))),
    ('2_smile.svg', face_key('Layered face key 2: a broad smile, the cheeks blush', (60, 63, 42, 42),
                             ((8, 42), (16, 37), (25, 41)), (16, 56, 7, 5.5), 3.5,
                             ((40, 80), (80, 80), 84, 104), blush=True)),
    ('3_surprised.svg', face_key('Layered face key 3: surprised: brows up, eyes wide, mouth open',
                                 (60, 60, 38, 47), ((8, 34), (16, 27), (25, 32)), (16, 53, 8, 10), 2.5,
                                 ((52, 88), (68, 88), 72, 108))),
])

# A walk painted as a cut-out character: six of the walk's poses, each part its own layer with its
# line work, painted back to front: neck, trousers, shirt, head (hair, eye), the arm (sleeve, hand,
# its ink). Where the arm hangs over the torso, the shirt is painted up to the arm's inner edge
# (under the arm there is only arm). The silhouette is the walk's own outline (examples/walk), as
# an unpainted class="outline" path, with its cut and marks: the union of the inked parts rounds
# the corners the marks sit on, and a mark's nearest point on that ink lands a hair (1e-6) from
# one of its vertices, which the mesher refuses. The parts are inset a little from the outline so
# that their edges cross the mesh's triangles: art running along the mesh boundary is not split
# at its vertices and would cut corners as a chord in the frames.
def inset(poly, delta):
    """The polygon with every edge moved `delta` inwards (corners where the moved edges meet)."""
    area = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(poly, poly[1:] + poly[:1]))
    side = 1 if area > 0 else -1
    out = []
    for i, p in enumerate(poly):
        a, b = poly[i - 1], poly[(i + 1) % len(poly)]
        e0 = ((p[0] - a[0]) / math.dist(a, p), (p[1] - a[1]) / math.dist(a, p))
        e1 = ((b[0] - p[0]) / math.dist(p, b), (b[1] - p[1]) / math.dist(p, b))
        n0, n1 = (-side * e0[1], side * e0[0]), (-side * e1[1], side * e1[0])
        if abs(e0[0] * e1[1] - e0[1] * e1[0]) < 1e-9:  # straight on
            out.append(add(p, n0, delta))
        else:
            out.append(intersect(add(p, n0, delta), e0, add(p, n1, delta), e1))
    return out

def walk_key(number, i):
    name, fr, bk, bob = step[i % 8]
    g = {}
    outline, cuts, marks = walker(fr, bk, arms[i], geo=g)
    T, d, n = g['T'], g['d'], g['n']
    c = (1, -66 - math.sqrt(105))  # the head's centre (radius 11)
    arm = inset([T, add(g['hand'], d, -0.15), add(add(g['corner'], d, -0.15), n, -0.15),
                 add(T, n, ARM_W - 0.15)], 0.15)
    wrist = [intersect(arm[0], d, add(T, d, ARM_L - 9), n), intersect(arm[3], d, add(T, d, ARM_L - 9), n)]
    if 'armpit' in g:
        front = [g['armpit']]
    else:
        front = [add(g['tip'], n, 0.15), add(add(g['corner'], n, 0.15), d, 0.15), (9, g['x'][1] + 0.2)]
    r = 10.85
    h0, h1 = add(c, (math.cos(math.radians(165)), math.sin(math.radians(165))), r), \
        add(c, (math.cos(math.radians(295)), math.sin(math.radians(295))), r)
    inked = lambda fill, w=1.2: 'fill="%s" stroke="%s" stroke-width="%s" stroke-linejoin="round"' % (fill, INK, f(w))
    pd = lambda ps: ('M ' + ' L '.join('%.2f %.2f' % p for p in ps) + ' Z').replace('.00', '')
    b = '  <g transform="translate(40 %s)">\n' % f(96 + bob)
    b += '    <path class="outline" fill="none" d="%s"/>\n' % outline
    b += '  ' + layer('rect', 'neck', inked('#e9b98f'), x='-2.85', y='-68', width='7.7', height='8')
    b += '  ' + layer('path', 'trousers', inked('#34406b'), d=pd(inset([(9, -16)] + g['legs'] + [(-9, -16)], 0.15)))
    b += '  ' + layer('path', 'shirt', inked('#d9503f'), d=pd(inset([(-9, -10), (-10, -56), (-3, -60), (5, -60), T] + front + [(9, -10)], 0.15)))
    b += '  ' + layer('circle', 'head', inked('#e9b98f'), cx=f(c[0]), cy='%.2f' % c[1], r=f(r))
    b += '  ' + layer('path', 'hair', 'fill="#3b2a1e"', d='M %.2f %.2f A %s %s 0 0 1 %.2f %.2f Q %s %s %.2f %.2f Z' % (
        h0[0], h0[1], f(r), f(r), h1[0], h1[1], f(c[0] - 2), f(c[1] - 3), h0[0], h0[1]))
    b += '  ' + layer('circle', 'eye', 'fill="%s"' % INK, cx=f(c[0] + 6), cy=f(c[1] - 1), r='1.3')
    b += '  ' + layer('path', 'sleeve', 'fill="#c2402f"', d=pd([arm[0], wrist[0], wrist[1], arm[3]]))
    b += '  ' + layer('path', 'hand', 'fill="#e9b98f"', d=pd([wrist[0], arm[1], arm[2], wrist[1]]))
    b += '  ' + layer('path', 'arm-ink', stroke(1), d=pd(arm))
    for cut in cuts:
        b += '    <path class="cut" d="%s" stroke="red" fill="none"/>\n' % polyline_d(cut)
    for k in sorted(marks):
        b += '    <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (k, f(marks[k][0]), f(marks[k][1]))
    b += '  </g>\n'
    return ('%d_%s.svg' % (number, name),
            svg(100, 160, 'Layered walk key %d: %s, arm at %d degrees (shirt, trousers, line work)' % (
                number, name, arms[i]), b))
write('layered_walk', [walk_key(k + 1, i) for k, i in enumerate((0, 3, 6, 8, 11, 14))],
      {'inbetween': {'timing': 'catmull_rom', 'frames': 36},
       'meshing': {'boundary_vertices': 560, 'max_edge_relative': 0.016}})

# The bird painted part by part: the body (a lighter belly on it) and the wing, each filled and
# inked, an eye and a beak. Folded, the wing lies on the body and the bird example's cut frees its
# trailing edge: the body is painted up to the cut, the wing from just beyond it.
def painted_bird(key, name, t1, t2):
    folded = t1 is None
    ink = 'stroke="%s" stroke-width="1.2" stroke-linejoin="round"' % INK
    if folded:  # the body round the wing: down its root to the cut's tip, up the cut's body side
        body = 'M 100 52 Q 96 42 86 42 L 76 44 L 61.9 50.1 L 48.9 44.1 L 12 44'
        wing = [(76, 44.2), (49.9, 44.2), (62.6, 49.8)]
    else:
        body = 'M 100 52 Q 96 42 86 42 L 76 44 L 62 44 L 12 44'
        wing = [(76, 44), t1, t2, (62, 44)]
    body += ' L 2 36 L 6 50 Q 30 70 70 64 Q 90 60 100 52 Z'
    b = layer('path', 'body', 'fill="#3f7fa8" ' + ink, d=body)
    b += layer('path', 'belly', 'fill="#cfe3ee"', d='M 14 52 Q 30 66 70 62 Q 88 58 96 53 Q 70 56 40 55 Q 24 54 14 52 Z')
    b += layer('path', 'wing', 'fill="#8fc0dc" ' + ink, d=polyline_d(wing, True))
    b += layer('path', 'beak', 'fill="#f0a830" stroke="%s" stroke-width="0.8" stroke-linejoin="round"' % INK,
               d='M 98 49 L 107 52.5 L 98 55 Z')
    b += layer('circle', 'eye', 'fill="%s"' % INK, cx='90', cy='48', r='1.8')
    if folded:
        b += '  <path class="cut" d="M 36 38 L 62 50" stroke="red" fill="none"/>\n'
    # 1 the wing's trailing root (the cut's tip when folded); along the outline, the upper edge of
    # the beak, the back before the wing and the tail's edges: without them the outline's arc length,
    # longer by the raised wing, would slide the head round towards the tail.
    for k, (x, y) in enumerate([(62, 50 if folded else 44), (102.5, 50.75), (81, 43), (7, 40), (4, 43)]):
        b += '  <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (k + 1, f(x), f(y))
    return ('%d_%s.svg' % (key, name), svg(110, 80, 'Layered bird key %d: wing %s' % (key, name), b))
write('layered_bird', [painted_bird(1, 'folded', None, None), painted_bird(2, 'raised', (30, 20), (24, 26)),
                       painted_bird(3, 'up', (44, 2), (38, 6))])

# Squash and stretch with paint: the ball (principles_squash_stretch) inked, with a stripe round
# its middle and a highlight; both squash and stretch with it, as they ride the ball's mesh.
def painted_ball(title, cx, cy, rx, ry):
    b = layer('ellipse', 'ball', 'fill="#d04a4a"', cx=f(cx), cy=f(cy), rx=f(rx), ry=f(ry))
    # the stripe: between two curves across the ball, its ends on the ball's outline
    e = lambda a: (cx + rx * math.cos(math.radians(a)), cy + ry * math.sin(math.radians(a)))
    (ax, ay), (bx, by), (cx2, cy2), (dx, dy) = e(190), e(350), e(15), e(165)
    b += layer('path', 'stripe', 'fill="#f4d35e"', d='M %s %s Q %s %s %s %s A %s %s 0 0 1 %s %s Q %s %s %s %s A %s %s 0 0 1 %s %s Z' % (
        f(ax), f(ay), f(cx), f(cy + 0.25 * ry), f(bx), f(by), f(rx), f(ry), f(cx2), f(cy2),
        f(cx), f(cy + 0.7 * ry), f(dx), f(dy), f(rx), f(ry), f(ax), f(ay)))
    b += layer('ellipse', 'highlight', 'fill="#ffffff" opacity="0.8"', cx=f(cx - 0.4 * rx), cy=f(cy - 0.45 * ry),
               rx=f(0.22 * rx), ry=f(0.16 * ry), transform='rotate(-30 %s %s)' % (f(cx - 0.4 * rx), f(cy - 0.45 * ry)))
    b += layer('ellipse', 'outline', stroke(2), cx=f(cx), cy=f(cy), rx=f(rx), ry=f(ry))
    # marks at the ends of the axes: each end of the ball stays that end in every key
    for k, (x, y) in enumerate([(cx + rx, cy), (cx, cy + ry), (cx - rx, cy), (cx, cy - ry)]):
        b += '  <circle data-corr="%d" cx="%s" cy="%s" r="1" fill="red"/>\n' % (k + 1, f(x), f(y))
    return svg(100, 120, title, b)
write('layered_squash_stretch', [
    ('1_round.svg', painted_ball('Layered squash and stretch key 1: ball at the top', 50, 24, 20, 20)),
    ('2_stretch.svg', painted_ball('Layered squash and stretch key 2: stretched as it falls', 50, 66, 14, 29)),
    ('3_squash.svg', painted_ball('Layered squash and stretch key 3: squashed on the ground', 50, 106, 30, 12)),
])
