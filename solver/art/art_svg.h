// SVG text for art layers (solver/core/art.h): one <path> per layer, in paint order, with its
// paint as SVG presentation attributes. For a frame renderer to put inside its <svg> element; the
// document, its viewBox and any background stay the renderer's.
#pragma once

#include <string>
#include <vector>

#include "solver/core/art.h"

namespace inbetween::solver {

// One line per painted layer: <path d="..." fill=... fill-opacity fill-rule stroke stroke-width
// stroke-linecap stroke-linejoin stroke-miterlimit stroke-dasharray stroke-dashoffset opacity/>,
// each attribute written only when it differs from SVG's initial value (fill="none" and
// stroke="none" always, so that the path does not inherit paint). All of a layer's subpaths go in
// one d, so its fill rule sees them together, as drawn; closed subpaths end with Z. Layers with
// neither fill nor stroke, or no point, are left out. data-layer carries the layer's name (not
// its id: a cross-fading frame draws two keys' layers of one id). Coordinates with 9 significant
// digits, enough for a drawing's units at any size a renderer uses.
std::string ArtToSvgPaths(const std::vector<ArtLayer>& layers);

}  // namespace inbetween::solver
