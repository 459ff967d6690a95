// Writes a file so that readers see either the old file or the complete new one: the bytes go
// to a temporary name next to it first and are renamed into place.
#pragma once

#include <filesystem>
#include <string_view>

#include "absl/status/status.h"

namespace inbetween::render {

absl::Status WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace inbetween::render
