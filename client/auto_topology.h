// `--auto-topology` for animate/mesh/optimize: when the drawings' topology differs, propose the
// cuts that bring them into one equivalence class (solver/geometry/auto_topology.h), add them to
// the project and write the project file so the artist can adjust them.
#pragma once

#include <filesystem>

#include "absl/status/status.h"
#include "client/project_file.h"

namespace inbetween::client {

// Imports every drawing (client-side, with the project's import settings, cuts and openings),
// proposes cuts and, when there are any, appends them to the drawings' cuts and writes the
// project to `write_to` (drawing paths relative to it). Prints each proposal and the file written
// on stderr unless `quiet`. Errors name the drawing; FAILED_PRECONDITION when no proposal is
// possible.
absl::Status ApplyAutoTopology(Project* project, const std::filesystem::path& write_to, bool quiet);

// Appends advice to a build error caused by differing topology ("... or pass --auto-topology").
absl::Status AdviseAutoTopology(const absl::Status& status);

}  // namespace inbetween::client
