// libFuzzer: project-file JSON (client/project_file.cpp). Bytes -> JSON (invalid JSON is
// skipped) -> ParseProject. No exception may escape; an accepted project must survive the round
// trip ProjectToJson -> ParseProject with the same drawings, marks and output settings.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "client/project_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace inbetween::client;
  const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, false);
  if (doc.is_discarded()) return 0;
  const std::filesystem::path base = "/nonexistent-fuzz-base";
  absl::StatusOr<Project> project = ParseProject(doc, base);
  if (!project.ok()) return 0;
  const nlohmann::json again = ProjectToJson(*project, base);
  absl::StatusOr<Project> reparsed = ParseProject(again, base);
  if (!reparsed.ok()) {
    std::fprintf(stderr, "round trip refused: %s\n%s\n", reparsed.status().ToString().c_str(),
                 again.dump().c_str());
    std::abort();
  }
  if (reparsed->drawings.size() != project->drawings.size() ||
      reparsed->correspondences != project->correspondences ||
      reparsed->output.formats != project->output.formats) {
    std::fprintf(stderr, "round trip changed the project:\n%s\n", again.dump().c_str());
    std::abort();
  }
  return 0;
}
