"""Tests of inbetween/art.py (the frame art rule, solver/art/frame_art.h) on hand-made headers; no
server. The parity with the C++ rule on real drawings is tests/art_parity.py (run by
tests/e2e/python_client_test.sh)."""

import unittest

import inbetween
from inbetween.v1 import inbetween_pb2 as pb

# A square of two triangles; vertex i at SQUARE[i] (frames move them).
TRIANGLES = [(0, 1, 2), (0, 2, 3)]
SQUARE = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
# Barycentric points (triangle, b0, b1, b2) at the square's vertices and centre.
V0, V1, V2, V3 = (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1), (1, 0, 0, 1)
CENTRE = (0, 0.5, 0, 0.5)


def layer(points, closed=True, fill=None, stroke=None, name="", opacity=1.0, stroke_width=1.0):
    """An EmbeddedArtLayer with one path; fill / stroke: 0xRRGGBB or None."""
    paint = pb.ArtLayer(name=name, opacity=opacity)
    if fill is not None:
        paint.fill.CopyFrom(pb.FillPaint(rgb=fill, opacity=1.0))
    if stroke is not None:
        paint.stroke.CopyFrom(pb.StrokePaint(rgb=stroke, opacity=1.0, width=stroke_width,
                                             miter_limit=4.0))
    return pb.EmbeddedArtLayer(paint=paint, paths=[pb.EmbeddedArtPath(
        triangles=[p[0] for p in points], barycentric=[b for p in points for b in p[1:]],
        closed=closed)])


def header(*keys):
    """An InbetweenHeader whose drawing k has the layers keys[k]."""
    h = pb.InbetweenHeader(keys=list(range(len(keys))), frames=len(keys))
    for a, b, c in TRIANGLES:
        h.triangles.add(a=a, b=b, c=c)
    for k, layers in enumerate(keys):
        h.art.add(key=k, layers=layers)
    return h


def frame(weights, vertices=SQUARE, index=0):
    return pb.InbetweenFrame(index=index, weights=weights,
                             vertices=[pb.Point(x=x, y=y) for x, y in vertices])


class FrameArtTest(unittest.TestCase):
    def test_key_frame_is_the_keys_art_placed(self):
        h = header([layer([V0, V1, V2], fill=0x112233, name="a", opacity=0.5),
                    layer([V3, CENTRE], closed=False, stroke=0x445566, stroke_width=2.0)],
                   [layer([V0, V2, V3], fill=0xFFFFFF)])
        moved = [(x + 1.0, 2.0 * y) for x, y in SQUARE]
        layers = inbetween.frame_art(h, frame([1.0, 0.0], moved))
        self.assertEqual(len(layers), 2)
        a, b = layers
        self.assertEqual((a.name, a.opacity, a.fill.rgb, a.stroke), ("a", 0.5, 0x112233, None))
        self.assertEqual(a.paths, [(True, [moved[0], moved[1], moved[2]])])
        self.assertEqual((b.fill, b.stroke.rgb, b.stroke.width), (None, 0x445566, 2.0))
        self.assertEqual(b.paths, [(False, [moved[3], (6.0, 10.0)])])
        last = inbetween.frame_art(h, frame([0.0, 1.0]))
        self.assertEqual([(l.fill.rgb, l.paths) for l in last],
                         [(0xFFFFFF, [(True, [SQUARE[0], SQUARE[2], SQUARE[3]])])])

    def test_corresponding_layers_morph_halfway(self):
        # An open path v0 -> v1 in key 0 and v0 -> v3 in key 1; black -> red.
        h = header([layer([V0, V1], closed=False, fill=0x000000, opacity=1.0)],
                   [layer([V0, V3], closed=False, fill=0xFF0000, opacity=0.5)])
        layers = inbetween.frame_art(h, frame([0.5, 0.5]))
        self.assertEqual(len(layers), 1)
        morph = layers[0]
        self.assertEqual(morph.paths, [(False, [(0.0, 0.0), (5.0, 5.0)])])
        self.assertEqual(morph.fill.rgb, 0x800000)  # 127.5 rounds half away from zero
        self.assertAlmostEqual(morph.opacity, 0.75)

    def test_cross_fade_opacity_and_draw_order(self):
        # The faces morph (both fills, one path); key 0's nose (stroke only) and key 1's mouth
        # (fill and stroke) and hat (stroke only, before its face) have no partner: they fade.
        face = [V0, V1, V2, V3]
        h = header([layer(face, fill=0xFFD700), layer([V0, CENTRE], False, stroke=0x111111)],
                   [layer([CENTRE, V2], False, stroke=0x222222, stroke_width=3.0, opacity=0.8),
                    layer(face, fill=0xFFD700),
                    layer([V1, V2, CENTRE], fill=0x333333, stroke=0x333333)])
        layers = inbetween.frame_art(h, frame([0.25, 0.75]))
        # The hat first (before every group), then the face, then key 0's nose, then key 1's
        # mouth (after the face in both keys: the lower key first).
        colours = [(l.fill and l.fill.rgb, l.stroke and l.stroke.rgb) for l in layers]
        self.assertEqual(colours, [(None, 0x222222), (0xFFD700, None), (None, 0x111111),
                                   (0x333333, 0x333333)])
        self.assertAlmostEqual(layers[0].opacity, 0.8 * 0.75)
        self.assertEqual(layers[1].opacity, 1.0)
        self.assertEqual(layers[2].opacity, 0.25)
        self.assertEqual(layers[3].opacity, 0.75)
        self.assertEqual(layers[0].stroke.width, 3.0)  # a faded layer keeps its paint
        self.assertEqual(layers[2].paths, [(False, [(0.0, 0.0), (5.0, 5.0)])])

    def test_named_layers_correspond_by_name_not_order(self):
        left, right = [V0, V1, CENTRE], [V2, V3, CENTRE]
        h = header([layer(left, fill=0xFF0000, name="left eye"),
                    layer(right, fill=0x0000FF, name="right eye")],
                   [layer(right, fill=0x0000FF, name="right eye"),
                    layer(left, fill=0xFF0000, name="left eye")])
        by_name = inbetween.frame_art(h, frame([0.5, 0.5]))
        self.assertEqual([(l.name, l.fill.rgb) for l in by_name],
                         [("left eye", 0xFF0000), ("right eye", 0x0000FF)])
        self.assertEqual(by_name[0].paths, [(True, [(0.0, 0.0), (10.0, 0.0), (5.0, 5.0)])])
        # Unnamed, the two pairs align in paint order: each eye morphs into the other.
        options = inbetween.FrameArtOptions(match_by_name=False)
        by_order = inbetween.frame_art(h, frame([0.5, 0.5]), options)
        self.assertEqual([l.fill.rgb for l in by_order], [0x800080, 0x800080])

    def test_closed_paths_drawn_from_other_corners_morph_in_place(self):
        # The square drawn v0 v1 v2 v3 in key 0, from v2 and the other way round in key 1: midway
        # it is the square, not a turned and shrunk one.
        h = header([layer([V0, V1, V2, V3], fill=0x204060)],
                   [layer([V2, V1, V0, V3], fill=0x204060)])
        layers = inbetween.frame_art(h, frame([0.5, 0.5]))
        self.assertEqual(len(layers), 1)
        closed, points = layers[0].paths[0]
        self.assertTrue(closed)
        self.assertEqual(sorted(points), sorted(SQUARE))

    def test_a_fill_that_gains_a_hole_morphs(self):
        # Key 1 adds a closed path (a hole); key 0's outline pairs with key 1's, and the hole is
        # placed as key 1 draws it: one layer at full opacity, not two fading ones.
        outline = layer([V0, V1, V2, V3], fill=0x204060)
        holed = layer([V0, V1, V2, V3], fill=0x204060)
        holed.paths.add(triangles=[0, 0, 1], barycentric=[0.6, 0.3, 0.1, 0.3, 0.6, 0.1,
                                                          0.3, 0.1, 0.6], closed=True)
        layers = inbetween.frame_art(header([outline], [holed]), frame([0.5, 0.5]))
        self.assertEqual(len(layers), 1)
        self.assertEqual(layers[0].opacity, 1.0)
        self.assertEqual(len(layers[0].paths), 2)

    def test_errors_and_no_art(self):
        h = header([layer([V0, V3], fill=0)], [layer([V0, V1, V2], fill=0)])
        with self.assertRaisesRegex(ValueError, "3 weights for the art of 2 keys"):
            inbetween.frame_art(h, frame([0.2, 0.3, 0.5]))
        with self.assertRaisesRegex(ValueError, "no key has a weight > 0"):
            inbetween.frame_art(h, frame([0.0, 0.0]))
        with self.assertRaisesRegex(ValueError, "uses vertex 3, the frame has 3"):
            inbetween.frame_art(h, frame([1.0, 0.0], SQUARE[:3]))
        self.assertEqual(inbetween.frame_art(header([], []), frame([0.5, 0.5])), [])

    def test_svg_draws_each_layer_as_the_cli_does(self):
        dashed = layer([V0, V1, V2], fill=0xABCDEF, stroke=0x010203, name='a&"b', opacity=0.5)
        dashed.paint.fill.even_odd = True
        dashed.paint.stroke.cap = pb.LINE_CAP_ROUND
        dashed.paint.stroke.dashes.extend([2.0, 1.0])
        dashed.paint.stroke.dash_offset = 0.5
        h = header([dashed, layer([V0, CENTRE], False, stroke=0xFF0000, stroke_width=0.1)])
        svg = inbetween.frame_art_svg(h, frame([1.0], index=7))
        self.assertEqual(svg, (
            '<svg xmlns="http://www.w3.org/2000/svg" viewBox="-0.5 -0.5 11 11">\n'
            "<!-- inbetween frame 7, time 0.000000 -->\n"
            '<path data-layer="a&amp;&quot;b" fill="#abcdef" fill-rule="evenodd"'
            ' stroke="#010203" stroke-width="1" stroke-linecap="round"'
            ' stroke-dasharray="2 1" stroke-dashoffset="0.5" opacity="0.5"'
            ' d="M0 0 L10 0 L10 10Z"/>\n'
            '<path fill="none" stroke="#ff0000" stroke-width="0.1" d="M0 0 L5 5"/>\n'
            "</svg>\n"))


if __name__ == "__main__":
    unittest.main()
