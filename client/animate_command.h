// `inbetween animate`: drawings in, frames out, through the gRPC API (embedded or remote).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "client/inbetween_client.h"

namespace inbetween::client {

struct AnimateOptions {
  std::vector<std::filesystem::path> drawings;  // 2..16 SVG files, in key order
  std::filesystem::path out_dir;
  uint32_t frames = 24;
  std::string method = "zhu17";  // linear | alexa | zhu17
  bool mesh_overlay = false;
  bool quiet = false;
};

// Runs create session -> put drawings -> build multimesh -> inbetween -> write files. Errors
// keep the server's status code and say which drawing/stage failed.
absl::Status RunAnimate(const AnimateOptions& options, InbetweenClient& client);

// Process exit code for a final status (documented in docs/cli.md).
int ExitCodeFor(const absl::Status& status);

}  // namespace inbetween::client
