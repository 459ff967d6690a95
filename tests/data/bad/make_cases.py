import json, os, sys
out = sys.argv[1]
os.makedirs(out, exist_ok=True)
S = "${session}"; V = "${version}"
def pts(*xy): return {"points": [{"x": x, "y": y} for x, y in xy]}
def outline(*xy): return {"kind": "ELEMENT_KIND_OUTLINE", "polyline": pts(*xy)}
def cut(*xy): return {"kind": "ELEMENT_KIND_CUT", "polyline": pts(*xy)}
def opening(*xy): return {"kind": "ELEMENT_KIND_OPENING", "polyline": pts(*xy)}
SQ = [(10, 10), (110, 10), (110, 110), (10, 110)]
def put_poly(elements, name="bad", topology=None, drawing_id=0):
    r = {"session_id": S, "expected_version": V,
         "drawing": {"name": name, "polylines": {"elements": elements}}}
    if drawing_id: r["drawing"]["id"] = drawing_id
    if topology: r["topology"] = topology
    return r
def put_svg(svg, name="bad.svg", topology=None, tol=None):
    r = {"session_id": S, "expected_version": V, "drawing": {"name": name, "svg": svg}}
    if topology: r["topology"] = topology
    if tol is not None: r["flatten_tolerance"] = tol
    return r
def svg(body): return '<svg xmlns="http://www.w3.org/2000/svg">' + body + '</svg>'
def step(rpc, request=None, code="INVALID_ARGUMENT", message="", **kw):
    s = {"rpc": rpc}
    if request is not None: s["request"] = request
    s.update(kw)
    s["expect"] = {"code": code, "message": message}
    return s
cases = {}
def case(name, description, steps, setup="empty", **kw):
    c = {"description": description, "setup": setup}
    c.update(kw)
    c["steps"] = steps
    cases[name] = c

# --- coordinates
case("coord_nan", "NaN coordinate in an outline point",
     [step("PutDrawing", put_poly([outline((0, 0), ("NaN", 0), (10, 10))]), message="drawing.polylines.elements[0] point 1 (nan, 0) is not finite")])
case("coord_inf", "+Infinity coordinate",
     [step("PutDrawing", put_poly([outline((0, 0), (10, 0), (10, "Infinity"))]), message="is not finite")])
case("coord_neg_inf", "-Infinity coordinate in a cut",
     [step("PutDrawing", put_poly([outline(*SQ), cut((50, 0), ("-Infinity", 50))]), message="elements[1] point 1")])
case("coord_1e308", "1e308 coordinate (finite but far beyond |x| <= 1e9)",
     [step("PutDrawing", put_poly([outline((0, 0), (1e308, 0), (0, 1e308))]), message="exceeds |coordinate| <= 1e9")])
case("svg_coord_1e308", "1e308 coordinate written in SVG path data",
     [step("PutDrawing", put_svg(svg('<path d="M 0 0 L 1e308 0 L 0 1e308 Z"/>')), message="exceeds |coordinate| <= 1e9")])
case("svg_transform_overflow", "a transform that overflows finite coordinates to infinity",
     [step("PutDrawing", put_svg(svg('<g transform="scale(1e300)"><rect x="0" y="0" width="1e10" height="1e10"/></g>')), message="drawing.svg: SVG element <g> (line 1): the transformed coordinates are not finite")])
case("key_time_nan", "drawing.key_time = NaN",
     [step("PutDrawing", dict(put_svg("${svg:square}"), drawing={"name": "k", "svg": "${svg:square}", "key_time": "NaN"}), message="key_time")])
case("flatten_tolerance_negative", "flatten_tolerance < 0",
     [step("PutDrawing", put_svg("${svg:square}", tol=-1), message="flatten_tolerance")])
case("gap_tolerance_too_large", "gap_tolerance above 0.1",
     [step("PutDrawing", dict(put_svg("${svg:square}"), gap_tolerance=0.5), message="gap_tolerance = 0.5 is not in (0, 0.1]")])
case("min_area_fraction_nan", "min_area_fraction = NaN",
     [step("PutDrawing", dict(put_svg("${svg:square}"), min_area_fraction="NaN"), message="min_area_fraction = nan is not finite")])
# --- paths
case("outline_empty", "an outline with no points",
     [step("PutDrawing", put_poly([outline()]), message="has 0 points, an outline needs at least 3")])
case("outline_one_point", "an outline with one point",
     [step("PutDrawing", put_poly([outline((5, 5))]), message="has 1 points, an outline needs at least 3")])
case("outline_two_points", "an outline with two points",
     [step("PutDrawing", put_poly([outline((5, 5), (6, 6))]), message="needs at least 3")])
case("svg_empty_path", "SVG whose only path has empty path data",
     [step("PutDrawing", put_svg(svg('<path d=""/>')), message="no filled shape")])
case("svg_one_point_path", "SVG whose only path is a single moveto",
     [step("PutDrawing", put_svg(svg('<path d="M 10 10"/>')), message="no filled shape")])
case("svg_bad_path_data", "SVG path data that does not parse",
     [step("PutDrawing", put_svg(svg('<path id="p" d="M 0 0 L x y Z"/>')), message="drawing.svg: SVG element <path id=\"p\"> (line 1): Invalid value")])
case("outline_zero_area_collinear", "three collinear points: zero area",
     [step("PutDrawing", put_poly([outline((0, 0), (10, 0), (20, 0))]), message="zero area")])
case("outline_zero_area_same_point", "every point the same",
     [step("PutDrawing", put_poly([outline((3, 3), (3, 3), (3, 3), (3, 3))]), message="elements[0] (4 points, 1 after merging near-duplicates) has 1 points, an outline needs at least 3")])
case("outline_self_intersecting", "a bow-tie outline",
     [step("PutDrawing", put_poly([outline((0, 0), (10, 10), (10, 0), (0, 20))]), message="crosses itself: segments")])
case("outline_duplicate_points", "a square with a repeated vertex and a repeated first point: cleaned, accepted",
     [step("PutDrawing", put_poly([outline((10, 10), (110, 10), (110, 10), (110, 110), (10, 110), (10, 10))]), code="OK", note="class 1 components 0 holes")])
case("outline_collinear_points", "a square with extra points along its edges: valid, accepted",
     [step("PutDrawing", put_poly([outline((10, 10), (60, 10), (110, 10), (110, 60), (110, 110), (10, 110))]), code="OK")])
case("outline_hole_only", "only a negative (hole) outline",
     [step("PutDrawing", put_poly([outline((10, 10), (10, 110), (110, 110), (110, 10))]), message="has no outer outline")])
case("element_kind_unspecified", "an element without a kind",
     [step("PutDrawing", put_poly([{"polyline": pts(*SQ)}]), message=".kind must be")])
case("outline_overlapping", "two outer outlines that overlap",
     [step("PutDrawing", put_poly([outline(*SQ), outline((50, 50), (150, 50), (150, 150), (50, 150))]), message="drawing 1")])
# --- cuts and openings
case("cut_outside_shape", "a cut entirely outside the shape",
     [step("PutDrawing", put_svg("${svg:square}", topology=[cut((200, 200), (300, 300))]), message="drawing 1")])
case("cuts_crossing", "two cuts crossing each other and the outline: split at the crossings (planar arrangement, S-Alg.1), accepted as 4 pieces",
     [step("PutDrawing", put_svg("${svg:square}", topology=[cut((60, 5), (60, 115)), cut((5, 60), (115, 60))]), code="OK", note="class 4 components 0 holes")])
case("cuts_crossing_inside", "two cuts crossing each other strictly inside the shape: accepted, still one piece",
     [step("PutDrawing", put_svg("${svg:square}", topology=[cut((60, 30), (60, 90)), cut((30, 60), (90, 60))]), code="OK", note="class 1 components 0 holes")])
case("cut_one_point", "a cut of one point",
     [step("PutDrawing", put_svg("${svg:square}", topology=[cut((60, 60))]), message="needs at least 2")])
case("opening_closes_nothing", "an opening outside the shape: it opens nothing",
     [step("PutDrawing", put_svg("${svg:square}", topology=[opening((200, 60), (280, 60))]), message="drawing 1")])
case("opening_floating", "an opening floating inside the shape, touching no boundary: a slit that becomes a hole",
     [step("PutDrawing", put_svg("${svg:square}", topology=[opening((40, 60), (80, 60))]), code="OK", note="class 1 components 1 holes")])
case("topology_with_id", "a new topology element with a non-zero id",
     [step("PutDrawing", put_svg("${svg:square}", topology=[dict(cut((60, 5), (60, 115)), id=7)]), message="new elements have id 0")])
case("topology_outline_kind", "an outline sent as a topology element",
     [step("PutDrawing", put_svg("${svg:square}", topology=[outline(*SQ)]), message="must be ELEMENT_KIND_CUT or ELEMENT_KIND_OPENING")])
case("edit_topology_unknown_element", "EditTopology deleting an element that does not exist",
     [{"rpc": "EditTopology", "edits": [{"session_id": S, "expected_version": V, "drawing_id": 1, "delete_element": 99}],
       "expect": {"code": "INVALID_ARGUMENT", "message": "edit 0: delete_element = 99 is not an element of drawing 1"}}], setup="one_drawing")
case("edit_topology_session_switch", "EditTopology whose second message names another session",
     [{"rpc": "EditTopology", "edits": [
         {"session_id": S, "expected_version": V, "drawing_id": 1, "add": cut((60, 5), (60, 115))},
         {"session_id": "someone-else", "expected_version": V, "drawing_id": 1, "delete_element": 2}],
       "expect": {"code": "INVALID_ARGUMENT", "message": "edit 1: session_id 'someone-else' differs"}}], setup="one_drawing")
case("edit_topology_crossing_cut", "EditTopology adding a cut that crosses an existing cut: split at the crossing, accepted",
     [{"rpc": "EditTopology", "edits": [
         {"session_id": S, "expected_version": V, "drawing_id": 1, "add": cut((60, 5), (60, 115))},
         {"session_id": S, "expected_version": V, "drawing_id": 1, "add": cut((5, 60), (115, 60))}],
       "expect": {"code": "OK"}}], setup="one_drawing")
case("edit_topology_unknown_drawing", "EditTopology on drawing 9 of a one-drawing session",
     [{"rpc": "EditTopology", "edits": [{"session_id": S, "expected_version": V, "drawing_id": 9, "delete_element": 1}],
       "expect": {"code": "NOT_FOUND", "message": "drawing 9"}}], setup="one_drawing")
# --- correspondences
case("correspondences_out_of_order", "two marks whose order along the boundary differs between the drawings",
     [step("SetCorrespondences", {"session_id": S, "expected_version": V, "correspondences": [
         {"points": [{"x": 10, "y": 10}, {"x": 115, "y": 60}]},
         {"points": [{"x": 110, "y": 110}, {"x": 32.5, "y": 12.369}]},
         {"points": [{"x": 10, "y": 110}, {"x": 87.5, "y": 107.631}]}]}, code="OK"),
      step("BuildMultimesh", {"session_id": S, "expected_version": V}, code="INVALID_ARGUMENT", message="order")],
     setup="two_drawings")
case("correspondence_wrong_count", "a mark with one point in a two-drawing session",
     [step("SetCorrespondences", {"session_id": S, "expected_version": V, "correspondences": [{"points": [{"x": 10, "y": 10}]}]}, message="correspondences[0] has 1 points")],
     setup="two_drawings")
case("correspondence_off_boundary", "a mark point far from drawing 2's boundary",
     [step("SetCorrespondences", {"session_id": S, "expected_version": V, "correspondences": [{"points": [{"x": 10, "y": 10}, {"x": 500, "y": 500}]}]}, code="OK"),
      step("BuildMultimesh", {"session_id": S, "expected_version": V}, message="drawing 2: correspondence mark 1 at (500, 500)")],
     setup="two_drawings")
case("correspondence_nan", "a NaN mark point",
     [step("SetCorrespondences", {"session_id": S, "expected_version": V, "correspondences": [{"points": [{"x": "NaN", "y": 10}, {"x": 5, "y": 60}]}]}, message="correspondences[0]")],
     setup="two_drawings")
# --- classes
ANNULUS = svg('<path fill-rule="evenodd" d="M 10 10 H 110 V 110 H 10 Z M 40 40 H 80 V 80 H 40 Z"/>')
case("different_equivalence_class_hole", "drawing 1 a disk, drawing 2 an annulus",
     [step("PutDrawing", put_svg(ANNULUS), code="OK"),
      step("BuildMultimesh", {"session_id": S, "expected_version": V}, code="INVALID_ARGUMENT", message="drawing 1: 1 component, 0 holes; drawing 2: 1 component, 1 hole")],
     setup="one_drawing")
case("correspondence_outline_to_hole", "a mark on the outline in drawing 1 and on the hole in drawing 2 (two annuli)",
     [step("PutDrawing", put_svg(ANNULUS, name="a.svg"), code="OK"),
      step("PutDrawing", put_svg(ANNULUS, name="b.svg"), code="OK"),
      step("SetCorrespondences", {"session_id": S, "expected_version": V, "correspondences": [{"points": [{"x": 10, "y": 60}, {"x": 40, "y": 60}]}]}, code="OK"),
      step("BuildMultimesh", {"session_id": S, "expected_version": V}, code="INVALID_ARGUMENT", message="drawing 2: correspondence mark 1 sits on a hole but on an outline in drawing 1")])
case("different_equivalence_class_components", "drawing 1 one component, drawing 2 two",
     [step("PutDrawing", put_svg(svg('<rect x="0" y="0" width="40" height="40"/><rect x="60" y="0" width="40" height="40"/>')), code="OK"),
      step("BuildMultimesh", {"session_id": S, "expected_version": V}, code="INVALID_ARGUMENT", message="drawing 2: 2 components, 0 holes")],
     setup="one_drawing")
# --- limits
case("drawing_10m_vertices", "a 10,000,000-vertex polyline drawing (200 MB serialized)",
     [{"rpc": "PutDrawing", "raw": {"huge_polyline_points": 10000000}, "expect": {"code": "RESOURCE_EXHAUSTED", "message": "larger than max"}}])
case("drawing_points_limit", "1,000,001 points: one over --max-drawing-points",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "big"}}, code="RESOURCE_EXHAUSTED", message="--max-drawing-points",
           generate={"name": "polyline_circle", "points": 1000001})])
case("drawing_max_points", "a 1,000,000-point circle: exactly the --max-drawing-points limit, accepted (the server's peak memory is checked by bad_input_test.sh)",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "max"}}, code="OK", note="class 1 components 0 holes",
           generate={"name": "polyline_circle", "points": 1000000})])
case("svg_flatten_bomb", "400 bytes of SVG (huge circles, tiny tolerance) that would flatten to over 10M points",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "bomb.svg"}, "flatten_tolerance": 1e-6}, code="RESOURCE_EXHAUSTED", message="drawing.svg: SVG has more than 1000000 points once its curves are flattened",
           generate={"name": "svg_flatten_bomb", "circles": 10, "radius": 1e8})])
case("svg_huge_path", "an SVG path of 2,000,000 commands",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "path.svg"}}, code="RESOURCE_EXHAUSTED", message="drawing.svg: SVG has more than 1000000 points in its path data (limit per drawing, --max-drawing-points)",
           generate={"name": "svg_huge_path", "commands": 2000000})])
# --- layered paint (docs/svg-convention.md, "Layers of paint")
case("svg_stroke_width_zero", "the only paint a stroke of width 0 (SVG draws nothing)",
     [step("PutDrawing", put_svg(svg('<path id="line" d="M0 0 L100 100" fill="none" stroke="#000" stroke-width="0"/>')), message="drawing.svg: SVG has no filled shape and no stroke: nothing is painted")])
case("svg_gradient_no_stops", "the only paint a gradient without stops (painted as none)",
     [step("PutDrawing", put_svg(svg('<defs><linearGradient id="g"/></defs><rect width="50" height="50" fill="url(#g)"/>')), message="nothing is painted")])
case("svg_hairlines_only", "a drawing of hairline strokes only (nowhere wider than the gap tolerance)",
     [step("PutDrawing", put_svg(svg('<path d="M0 0 L400 400 M0 400 L400 0" fill="none" stroke="#000" stroke-width="0.3"/><path d="M0 200 H400" fill="none" stroke="#f00" stroke-width="0.3"/>')), message="nowhere wider than the gap tolerance")])
case("svg_many_layers", "a drawing of 1,000,000 painted layers (40 MB of SVG)",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "layers.svg"}}, code="RESOURCE_EXHAUSTED", message="drawing.svg: SVG has more than 100000 painted layers",
           generate={"name": "svg_many_layers", "layers": 1000000})])
case("outline_comb", "a simple comb outline of 64,002 points whose 32,000 teeth overlap in x: crossing checks bounded, refused in about a second",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "comb"}}, code="RESOURCE_EXHAUSTED", message="too many long segments side by side",
           generate={"name": "polyline_comb", "teeth": 16000})])
case("outline_comb_small", "the same comb with 2,000 teeth (8,002 points): within the bound, accepted",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "comb"}}, code="OK", note="class 1 components 0 holes",
           generate={"name": "polyline_comb", "teeth": 2000})])
case("svg_use_bomb", "<use> fan-out: 10 levels of 10 uses = 10^10 copies of a rect",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "use.svg"}}, code="RESOURCE_EXHAUSTED", message="drawing.svg: SVG element <use> (line 1): <use> expansion makes more than 100000 elements",
           generate={"name": "svg_use_bomb", "levels": 10, "fanout": 10})])
case("frames_1e9", "Inbetween with parameters.frames = 1e9",
     [step("Inbetween", {"session_id": S, "parameters": {"frames": 1000000000}}, code="RESOURCE_EXHAUSTED", message="frames")],
     setup="meshed")
case("frames_one", "Inbetween with parameters.frames = 1",
     [step("Inbetween", {"session_id": S, "parameters": {"frames": 1}}, message="frames = 1")], setup="meshed")
case("start_frame_out_of_range", "Inbetween resuming past the last frame",
     [step("Inbetween", {"session_id": S, "parameters": {"frames": 10}, "start_frame": 10}, message="start_frame")], setup="meshed")
case("parameters_nan_tau", "Inbetween with tau = NaN",
     [step("Inbetween", {"session_id": S, "parameters": {"tau": "NaN"}}, message="tau")], setup="meshed")
case("parameters_negative_lambda", "Inbetween with lambda = -1",
     [step("Inbetween", {"session_id": S, "parameters": {"lambda": -1}}, message="lambda")], setup="meshed")
case("meshing_huge_boundary_vertices", "BuildMultimesh asking for 4e9 boundary vertices",
     [step("BuildMultimesh", {"session_id": S, "expected_version": V, "meshing": {"boundary_vertices": 4000000000}}, message="boundary_vertices")], setup="two_drawings")
# --- XML
case("svg_nested_groups", "100,000 nested <g> elements",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "deep.svg"}}, message="not well-formed",
           generate={"name": "svg_nested_groups", "depth": 100000})])
LAUGHS = ('<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY a "aaaaaaaaaa">' +
          "".join('<!ENTITY %s "%s">' % (chr(ord("b") + i), ("&%s;" % chr(ord("a") + i)) * 10) for i in range(8)) +
          ']><svg xmlns="http://www.w3.org/2000/svg"><rect x="0" y="0" width="10" height="10" class="&i;"/><text>&i;</text></svg>')
case("xml_billion_laughs", "entity expansion (billion laughs, 10^9 bytes if expanded)",
     [step("PutDrawing", put_svg(LAUGHS), message="not well-formed")])
case("xml_external_entity", "an external entity reading a local file",
     [step("PutDrawing", put_svg('<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY x SYSTEM "file:///etc/passwd">]><svg xmlns="http://www.w3.org/2000/svg"><rect x="0" y="0" width="10" height="10"/><text>&x;</text></svg>'),
           message="entity references are not supported")])
case("xml_external_dtd", "an external DTD on an unreachable loopback port: never fetched, drawing accepted",
     [step("PutDrawing", put_svg('<?xml version="1.0"?><!DOCTYPE svg SYSTEM "http://127.0.0.1:9/x.dtd"><svg xmlns="http://www.w3.org/2000/svg"><rect x="0" y="0" width="10" height="10"/></svg>'), code="OK")])
case("xml_parameter_entity", "a parameter entity pulling an external DTD subset",
     [step("PutDrawing", put_svg('<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY % ext SYSTEM "file:///etc/passwd"> %ext;]><svg xmlns="http://www.w3.org/2000/svg"><rect x="0" y="0" width="10" height="10"/></svg>'),
           code="ANY")])
case("svg_huge_attribute", "a 12 MB attribute value",
     [step("PutDrawing", {"session_id": S, "expected_version": V, "drawing": {"name": "attr.svg"}}, message="not well-formed",
           generate={"name": "svg_huge_attribute", "bytes": 12000000})])
case("svg_not_xml", "text that is not XML",
     [step("PutDrawing", put_svg("hello, this is not a drawing"), message="not well-formed")])
case("svg_wrong_root", "an XML document whose root is not <svg>",
     [step("PutDrawing", put_svg("<html><body/></html>"), message="root element must be <svg>")])
case("svg_empty_string", "an empty SVG string",
     [step("PutDrawing", put_svg(""), message=".svg is empty")])
case("svg_use_self_reference", "<use> referencing its own ancestor",
     [step("PutDrawing", put_svg(svg('<g id="g"><rect x="0" y="0" width="5" height="5"/><use href="#g" x="10"/></g>')), message="nested too deeply")])
case("svg_use_unknown_id", "<use> of an id that does not exist",
     [step("PutDrawing", put_svg(svg('<use href="#nope"/>')), message="unknown id")])
case("drawing_name_too_long", "a 100 kB drawing name",
     [step("PutDrawing", put_svg("${svg:square}"), message=".name is 100000 bytes",
           generate={"name": "long_name", "bytes": 100000})])
# --- sessions
case("wrong_session_version", "PutDrawing with a stale expected_version",
     [step("PutDrawing", dict(put_svg("${svg:square}"), expected_version="${stale_version}"), code="ABORTED", message="version")], setup="one_drawing")
case("delete_wrong_version", "DeleteSession with a stale expected_version",
     [step("DeleteSession", {"session_id": S, "expected_version": "${stale_version}"}, code="ABORTED", message="version")], setup="one_drawing")
case("unknown_session", "GetSession of an id that was never created",
     [step("GetSession", {"session_id": "no-such-session"}, code="NOT_FOUND", message="session no-such-session not found")], setup="none")
case("unknown_session_inbetween", "Inbetween on an id that was never created",
     [step("Inbetween", {"session_id": "no-such-session"}, code="NOT_FOUND", message="not found")], setup="none")
case("session_id_bad_characters", "a session id with characters outside [A-Za-z0-9_-] (a path): looked up, never used as a path",
     [step("GetSession", {"session_id": "../../etc/passwd"}, code="NOT_FOUND", message="not found")], setup="none")
case("session_id_missing", "PutDrawing without a session id",
     [step("PutDrawing", {"drawing": {"name": "x", "svg": "${svg:square}"}}, code="INVALID_ARGUMENT", message="session_id is required", session_header=False)], setup="none")
case("other_token_session", "another token reads, edits, animates and deletes the session: NOT_FOUND every time",
     [step("GetSession", {"session_id": S}, code="NOT_FOUND", message="not found", token="other"),
      step("PutDrawing", put_svg("${svg:square}"), code="NOT_FOUND", message="not found", token="other"),
      step("Inbetween", {"session_id": S}, code="NOT_FOUND", message="not found", token="other"),
      step("DeleteSession", {"session_id": S}, code="NOT_FOUND", message="not found", token="other"),
      step("ListSessions", {}, code="OK", token="other"),
      step("GetSession", {"session_id": S}, code="OK")], setup="meshed")
case("no_token", "a call without a bearer token",
     [step("ListSessions", {}, code="UNAUTHENTICATED", message="bearer", token="none")], setup="none")
case("bogus_token", "a call with an unknown bearer token",
     [step("CreateSession", {}, code="UNAUTHENTICATED", message="invalid bearer token", token="bogus")], setup="none")
case("concurrent_edits", "8 PutDrawing calls with the same expected_version at once: one wins, 7 ABORTED",
     [{"rpc": "PutDrawing", "concurrent": True, "count": 8, "request": put_svg("${svg:hexagon}"), "expect": {"code": "ABORTED", "message": "version"}}], setup="one_drawing")
case("import_garbage_archive", "ImportSession of bytes that are not an archive",
     [step("ImportSession", {"data": "aGVsbG8gd29ybGQ="}, message="data")], setup="none")
case("remove_unknown_drawing", "RemoveDrawing of drawing 42",
     [step("RemoveDrawing", {"session_id": S, "expected_version": V, "drawing_id": 42}, code="NOT_FOUND", message="drawing 42")], setup="one_drawing")
case("replace_unknown_drawing", "PutDrawing replacing drawing 42, which does not exist",
     [step("PutDrawing", dict(put_svg("${svg:square}"), drawing={"id": 42, "name": "x", "svg": "${svg:square}"}), code="NOT_FOUND", message="drawing 42")], setup="one_drawing")
# --- stages and streams
case("inbetween_before_build", "Inbetween before BuildMultimesh",
     [step("Inbetween", {"session_id": S}, code="FAILED_PRECONDITION", message="BuildMultimesh")], setup="two_drawings")
case("build_one_drawing", "BuildMultimesh with a single drawing",
     [step("BuildMultimesh", {"session_id": S, "expected_version": V}, code="FAILED_PRECONDITION", message="at least 2 drawings")], setup="one_drawing")
case("inbetween_cancelled", "the client cancels an Inbetween stream after 3 messages",
     [step("Inbetween", {"session_id": S, "parameters": {"frames": 2000}}, code="CANCELLED", cancel_after=3)], setup="meshed")
case("inbetween_abandoned", "the client drops an Inbetween stream after 2 messages without finishing it; the session still answers",
     [step("Inbetween", {"session_id": S, "parameters": {"frames": 2000}}, code="CANCELLED", message="abandoned", abandon_after=2),
      step("GetSession", {"session_id": S}, code="OK")], setup="meshed")
case("inbetween_deadline", "an Inbetween stream with a 50 ms deadline",
     [step("Inbetween", {"session_id": S, "parameters": {"frames": 20000}}, code="DEADLINE_EXCEEDED", deadline_ms=50)], setup="meshed")
case("build_cancelled", "the client cancels BuildMultimesh after its first message",
     [step("BuildMultimesh", {"session_id": S, "expected_version": V}, code="ANY", cancel_after=1),
      step("GetSession", {"session_id": S}, code="OK")], setup="two_drawings")
case("optimize_abandoned", "the client drops OptimizeComesh after its first message",
     [step("OptimizeComesh", {"session_id": S, "expected_version": V}, code="CANCELLED", abandon_after=1),
      step("GetSession", {"session_id": S}, code="OK")], setup="meshed")
# --- truncated / malformed wire messages
case("truncated_put_drawing", "a PutDrawing request cut 5 bytes short (inside a length-delimited field)",
     [{"rpc": "PutDrawing", "request": put_svg("${svg:square}"), "raw": {"truncate": 5}, "expect": {"code": "INVALID_ARGUMENT", "message": "the request message could not be parsed"}}], setup="empty")
case("truncated_inbetween", "an Inbetween request cut 1 byte short",
     [{"rpc": "Inbetween", "request": {"session_id": S, "parameters": {"frames": 10}}, "raw": {"truncate": 1}, "expect": {"code": "INVALID_ARGUMENT", "message": "the request message could not be parsed"}}], setup="meshed")
case("garbage_wire_bytes", "a CreateSession request followed by an invalid wire type (field 1, type 7)",
     [{"rpc": "CreateSession", "request": {"display_name": "x"}, "raw": {"append_hex": "0f"}, "expect": {"code": "INVALID_ARGUMENT", "message": "the request message could not be parsed"}}], setup="none")
for name, c in cases.items():
    with open(os.path.join(out, name + ".json"), "w") as f:
        json.dump(c, f, indent=1)
        f.write("\n")
print(len(cases), "cases")
