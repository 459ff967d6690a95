// --auto-topology (see auto_topology.h).
#include "client/auto_topology.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/auto_topology.h"
#include "solver/io/svg_import.h"

namespace inbetween::client {
namespace {

solver::Points ToPoints(const XYs& line) {
  solver::Points out;
  for (const XY& p : line) out.emplace_back(p[0], p[1]);
  return out;
}

}  // namespace

absl::Status ApplyAutoTopology(Project* project, const std::filesystem::path& write_to,
                               bool quiet) {
  // The project's import settings, as the server reads them (unset = ImportSvg's default).
  solver::SvgImportOptions options;
  const ImportSettings& settings = project->import_settings;
  options.gap_tolerance = settings.gap_tolerance.value_or(options.gap_tolerance);
  options.min_area_fraction = settings.min_area_fraction.value_or(options.min_area_fraction);
  std::vector<solver::Drawing> drawings;
  for (size_t i = 0; i < project->drawings.size(); ++i) {
    const ProjectDrawing& d = project->drawings[i];
    const std::string where = absl::StrCat("drawing ", i + 1, " (", d.file.string(), ")");
    std::ifstream in(d.file, std::ios::binary);
    if (!in) return absl::NotFoundError(absl::StrCat(where, ": cannot open"));
    std::ostringstream text;
    text << in.rdbuf();
    absl::StatusOr<solver::Drawing> drawing = solver::ImportSvg(text.str(), options);
    if (!drawing.ok()) {
      return absl::Status(drawing.status().code(),
                          absl::StrCat(where, ": ", drawing.status().message()));
    }
    for (const XYs& cut : d.cuts) drawing->cuts.push_back(ToPoints(cut));
    for (const XYs& opening : d.openings) drawing->openings.push_back(ToPoints(opening));
    drawings.push_back(*std::move(drawing));
  }
  absl::StatusOr<solver::AutoTopologyResult> proposal = solver::ProposeTopology(drawings);
  if (!proposal.ok()) return proposal.status();
  if (proposal->notes.empty()) {
    if (!quiet) {
      std::fprintf(stderr, "auto-topology: every drawing has %s; nothing to add\n",
                   proposal->target.ToString().c_str());
    }
    return absl::OkStatus();
  }
  for (size_t i = 0; i < project->drawings.size(); ++i) {
    for (const solver::Points& cut : proposal->cuts[i]) {
      XYs line;
      for (const solver::Point& p : cut) line.push_back({p.x(), p.y()});
      project->drawings[i].cuts.push_back(std::move(line));
    }
  }
  // Write the project (temp file, then rename) so the artist can adjust the cuts.
  const std::filesystem::path target = std::filesystem::absolute(write_to);
  std::error_code ec;
  std::filesystem::create_directories(target.parent_path(), ec);
  Project written = *project;
  for (ProjectDrawing& d : written.drawings) d.file = std::filesystem::absolute(d.file);
  const std::filesystem::path tmp = target.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << ProjectToJson(written, target.parent_path()).dump(2) << "\n";
    if (!out.flush()) {
      return absl::UnavailableError(absl::StrCat("cannot write ", tmp.string()));
    }
  }
  std::filesystem::rename(tmp, target, ec);
  if (ec) return absl::UnavailableError(absl::StrCat("cannot write ", target.string()));
  if (!quiet) {
    for (const std::string& note : proposal->notes) {
      std::fprintf(stderr, "auto-topology: %s\n", note.c_str());
    }
    std::fprintf(stderr,
                 "auto-topology: every drawing now has %s; the cuts are in %s (adjust them there "
                 "and use --project)\n",
                 proposal->target.ToString().c_str(), write_to.string().c_str());
  }
  return absl::OkStatus();
}

absl::Status AdviseAutoTopology(const absl::Status& status) {
  if (solver::ErrorReason(status) != solver::kReasonTopologyDiffers) {
    return status;
  }
  return absl::Status(
      status.code(),
      absl::StrCat(status.message(),
                   " (\"cuts\"/\"openings\" of the drawing in the project file, see "
                   "docs/project-file.md); or pass --auto-topology to let inbetween propose the "
                   "cuts and write them to the project file"));
}

}  // namespace inbetween::client
