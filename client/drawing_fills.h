// The key drawings' own fill colours, read on the client from the SVG text (the service only
// keeps geometry), so frames.json and every render can carry them (docs/file-formats.md).
#pragma once

#include <string>
#include <vector>

#include "client/render/color.h"

namespace inbetween::client {

// One colour per drawing: the plain fill of its largest filled shape (solver::ImportSvg's
// SvgImportInfo::fill_rgb). A drawing without one takes the first drawing's colour that has one;
// empty when no drawing has one or a drawing does not import (the import reports that later).
std::vector<render::Rgba8> DrawingFills(const std::vector<std::string>& svg_texts);

}  // namespace inbetween::client
