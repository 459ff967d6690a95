// Project file parsing and writing (see project_file.h and docs/project-file.md).
#include "client/project_file.h"

#include <cmath>
#include <fstream>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "client/render/color.h"

namespace inbetween::client {
namespace {

using nlohmann::json;

// A cursor into the document that knows its JSON path, so every error can say where it is.
class Node {
 public:
  Node(const json& value, std::string path) : value_(value), path_(std::move(path)) {}

  const json& value() const { return value_; }
  const std::string& path() const { return path_; }

  absl::Status Error(const std::string& what) const {
    return absl::InvalidArgumentError(absl::StrCat(path_, ": ", what));
  }
  absl::Status TypeError(const char* expected) const {
    return Error(absl::StrCat("expected ", expected, ", got ", value_.type_name()));
  }

  // Fails on any key not in `known`.
  absl::Status CheckKeys(std::initializer_list<const char*> known) const {
    if (!value_.is_object()) return TypeError("an object");
    std::set<std::string> allowed(known.begin(), known.end());
    for (const auto& [key, unused] : value_.items()) {
      if (allowed.count(key) == 0) {
        return absl::InvalidArgumentError(absl::StrCat(
            path_, ".", key, ": unknown field (known: ", absl::StrJoin(allowed, ", "), ")"));
      }
    }
    return absl::OkStatus();
  }
  bool Has(const char* key) const { return value_.contains(key); }
  Node Child(const char* key) const { return Node(value_.at(key), absl::StrCat(path_, ".", key)); }
  Node Item(size_t i) const { return Node(value_.at(i), absl::StrCat(path_, "[", i, "]")); }

  absl::StatusOr<double> Number(double min, double max) const {
    if (!value_.is_number()) return TypeError("a number");
    const double v = value_.get<double>();
    if (!std::isfinite(v) || v < min || v > max) {
      return Error(absl::StrCat("value ", v, " out of range [", min, ", ", max, "]"));
    }
    return v;
  }
  absl::StatusOr<int64_t> Integer(int64_t min, int64_t max) const {
    if (!value_.is_number_integer()) return TypeError("an integer");
    const int64_t v = value_.get<int64_t>();
    if (v < min || v > max) {
      return Error(absl::StrCat("value ", v, " out of range [", min, ", ", max, "]"));
    }
    return v;
  }
  absl::StatusOr<std::string> String() const {
    if (!value_.is_string()) return TypeError("a string");
    return value_.get<std::string>();
  }
  absl::StatusOr<bool> Bool() const {
    if (!value_.is_boolean()) return TypeError("a boolean");
    return value_.get<bool>();
  }
  absl::Status Array() const {
    return value_.is_array() ? absl::OkStatus() : TypeError("an array");
  }

  absl::StatusOr<XY> Point() const {
    if (!value_.is_array() || value_.size() != 2) return TypeError("a point [x, y]");
    XY p;
    for (size_t i = 0; i < 2; ++i) {
      auto c = Item(i).Number(-1e9, 1e9);
      if (!c.ok()) return c.status();
      p[i] = *c;
    }
    return p;
  }
  absl::StatusOr<XYs> Polyline(size_t min_points) const {
    if (absl::Status s = Array(); !s.ok()) return s;
    if (value_.size() < min_points) {
      return Error(absl::StrCat("needs at least ", min_points, " points, has ", value_.size()));
    }
    XYs out;
    for (size_t i = 0; i < value_.size(); ++i) {
      auto p = Item(i).Point();
      if (!p.ok()) return p.status();
      out.push_back(*p);
    }
    return out;
  }

 private:
  const json& value_;
  std::string path_;
};

#define PROJECT_ASSIGN_OR_RETURN(lhs, expr)     \
  auto lhs##_or = (expr);                       \
  if (!lhs##_or.ok()) return lhs##_or.status(); \
  auto lhs = *std::move(lhs##_or)

absl::Status ParsePolylines(const Node& node, std::vector<XYs>* out) {
  if (absl::Status s = node.Array(); !s.ok()) return s;
  for (size_t i = 0; i < node.value().size(); ++i) {
    PROJECT_ASSIGN_OR_RETURN(line, node.Item(i).Polyline(2));
    out->push_back(std::move(line));
  }
  return absl::OkStatus();
}

absl::Status ParseDrawing(const Node& node, const std::filesystem::path& base_dir,
                          ProjectDrawing* out) {
  if (node.value().is_string()) {  // shorthand: just the file
    out->file = base_dir / node.value().get<std::string>();
    return absl::OkStatus();
  }
  if (absl::Status s = node.CheckKeys({"file", "key_time", "cuts", "openings"}); !s.ok()) return s;
  if (!node.Has("file")) return node.Error("missing field 'file'");
  PROJECT_ASSIGN_OR_RETURN(file, node.Child("file").String());
  out->file = base_dir / file;
  if (node.Has("key_time")) {
    PROJECT_ASSIGN_OR_RETURN(t, node.Child("key_time").Number(0.0, 1.0));
    out->key_time = t;
  }
  if (node.Has("cuts")) {
    if (absl::Status s = ParsePolylines(node.Child("cuts"), &out->cuts); !s.ok()) return s;
  }
  if (node.Has("openings")) {
    if (absl::Status s = ParsePolylines(node.Child("openings"), &out->openings); !s.ok()) return s;
  }
  return absl::OkStatus();
}

// meshing.corner_matching's names, indexed by v1::CornerMatching (0: unspecified).
constexpr const char* kCornerMatchings[] = {"when_arc_length_fails", "when_arc_length_fails",
                                            "never", "always"};

absl::StatusOr<v1::CornerMatching> CornerMatchingFromName(const Node& node) {
  PROJECT_ASSIGN_OR_RETURN(name, node.String());
  for (int k = v1::CORNER_MATCHING_WHEN_ARC_LENGTH_FAILS; k <= v1::CORNER_MATCHING_ALWAYS; ++k) {
    if (name == kCornerMatchings[k]) return static_cast<v1::CornerMatching>(k);
  }
  return node.Error(absl::StrCat("unknown corner matching '", name,
                                 "' (when_arc_length_fails, never, always)"));
}

// meshing.boundary_alignment's names, indexed by v1::BoundaryAlignment (0: unspecified).
constexpr const char* kBoundaryAlignments[] = {"features", "features", "arc_length"};

absl::StatusOr<v1::BoundaryAlignment> BoundaryAlignmentFromName(const Node& node) {
  PROJECT_ASSIGN_OR_RETURN(name, node.String());
  for (int k = v1::BOUNDARY_ALIGNMENT_FEATURES; k <= v1::BOUNDARY_ALIGNMENT_ARC_LENGTH; ++k) {
    if (name == kBoundaryAlignments[k]) return static_cast<v1::BoundaryAlignment>(k);
  }
  return node.Error(
      absl::StrCat("unknown boundary alignment '", name, "' (features, arc_length)"));
}

absl::Status ParseMeshing(const Node& node, v1::MeshingParameters* out) {
  if (absl::Status s = node.CheckKeys({"boundary_vertices", "max_edge_relative", "shape_bound",
                                       "corner_matching", "boundary_tolerance",
                                       "boundary_alignment"});
      !s.ok()) {
    return s;
  }
  if (node.Has("boundary_tolerance")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("boundary_tolerance").Number(0.0, 0.1));
    out->set_boundary_tolerance(v);
  }
  if (node.Has("boundary_alignment")) {
    PROJECT_ASSIGN_OR_RETURN(v, BoundaryAlignmentFromName(node.Child("boundary_alignment")));
    out->set_boundary_alignment(v);
  }
  if (node.Has("boundary_vertices")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("boundary_vertices").Integer(8, 100000));
    out->set_boundary_vertices(static_cast<uint32_t>(v));
  }
  if (node.Has("max_edge_relative")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("max_edge_relative").Number(1e-6, 1.0));
    out->set_max_edge_relative(v);
  }
  if (node.Has("shape_bound")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("shape_bound").Number(1e-6, 0.125));
    out->set_shape_bound(v);
  }
  if (node.Has("corner_matching")) {
    PROJECT_ASSIGN_OR_RETURN(v, CornerMatchingFromName(node.Child("corner_matching")));
    out->set_corner_matching(v);
  }
  return absl::OkStatus();
}

absl::Status ParseComesh(const Node& node, v1::ComeshParameters* out) {
  if (absl::Status s = node.CheckKeys(
          {"map_weight", "max_outer_iterations", "max_inner_iterations", "tolerance",
           "outer_tolerance", "outline_corner_degrees", "min_quality", "slide_window"});
      !s.ok()) {
    return s;
  }
  if (node.Has("map_weight")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("map_weight").Number(0.0, 1.0));
    out->set_map_weight(v);
  }
  if (node.Has("max_outer_iterations")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("max_outer_iterations").Integer(1, 1000));
    out->set_max_outer_iterations(static_cast<uint32_t>(v));
  }
  if (node.Has("max_inner_iterations")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("max_inner_iterations").Integer(1, 100000));
    out->set_max_inner_iterations(static_cast<uint32_t>(v));
  }
  if (node.Has("tolerance")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("tolerance").Number(1e-15, 0.999));
    out->set_tolerance(v);
  }
  if (node.Has("outer_tolerance")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("outer_tolerance").Number(0.0, 0.999));
    out->set_outer_tolerance(v);
  }
  if (node.Has("outline_corner_degrees")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("outline_corner_degrees").Number(0.0, 180.0));
    out->set_outline_corner_degrees(v);
  }
  if (node.Has("min_quality")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("min_quality").Number(0.0, 0.999));
    out->set_min_quality(v);
  }
  if (node.Has("slide_window")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("slide_window").Number(0.0, 100.0));
    out->set_slide_window(v);
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::Method> MethodFromName(const Node& node) {
  PROJECT_ASSIGN_OR_RETURN(name, node.String());
  if (name == "linear") return v1::METHOD_LINEAR;
  if (name == "alexa") return v1::METHOD_ALEXA;
  if (name == "zhu17") return v1::METHOD_ZHU17;
  return node.Error(absl::StrCat("unknown method '", name, "' (linear, alexa, zhu17)"));
}

absl::StatusOr<v1::TimingCurve> CurveFromName(const Node& node) {
  PROJECT_ASSIGN_OR_RETURN(name, node.String());
  if (auto curve = TimingCurveFromName(name)) return *curve;
  return node.Error(
      absl::StrCat("unknown timing curve '", name, "' (linear, catmull_rom, ease_in_out)"));
}

absl::Status ParseInbetween(const Node& node, v1::InbetweenParameters* out) {
  if (absl::Status s =
          node.CheckKeys({"method", "frames", "timing", "ease", "stiffness", "lambda", "tau",
                          "alpha", "epsilon", "rho", "timestep", "max_iterations"});
      !s.ok()) {
    return s;
  }
  if (node.Has("method")) {
    PROJECT_ASSIGN_OR_RETURN(m, MethodFromName(node.Child("method")));
    out->set_method(m);
  }
  if (node.Has("frames")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("frames").Integer(2, 100000));
    out->set_frames(static_cast<uint32_t>(v));
  }
  if (node.Has("timing")) {
    PROJECT_ASSIGN_OR_RETURN(c, CurveFromName(node.Child("timing")));
    out->set_timing(c);
  }
  if (node.Has("ease")) {
    Node ease = node.Child("ease");
    if (absl::Status s = ease.Array(); !s.ok()) return s;
    for (size_t i = 0; i < ease.value().size(); ++i) {
      PROJECT_ASSIGN_OR_RETURN(v, ease.Item(i).Number(0.0, 1.0));
      out->add_ease(v);
    }
  }
  if (node.Has("stiffness")) {
    Node regions = node.Child("stiffness");
    if (absl::Status s = regions.Array(); !s.ok()) return s;
    for (size_t i = 0; i < regions.value().size(); ++i) {
      Node region = regions.Item(i);
      if (absl::Status s = region.CheckKeys({"polygon", "kappa"}); !s.ok()) return s;
      if (!region.Has("polygon") || !region.Has("kappa")) {
        return region.Error("needs 'polygon' and 'kappa'");
      }
      PROJECT_ASSIGN_OR_RETURN(polygon, region.Child("polygon").Polyline(3));
      PROJECT_ASSIGN_OR_RETURN(kappa, region.Child("kappa").Number(1e-9, 1e6));
      v1::StiffnessRegion* r = out->add_stiffness();
      for (const XY& p : polygon) {
        v1::Point* q = r->mutable_polygon()->add_points();
        q->set_x(p[0]);
        q->set_y(p[1]);
      }
      r->set_kappa(kappa);
    }
  }
  struct Bounded {
    const char* key;
    double min, max;
    void (v1::InbetweenParameters::*set)(double);
  };
  for (const Bounded& b :
       {Bounded{"lambda", 0.0, 1e9, &v1::InbetweenParameters::set_lambda},
        Bounded{"tau", 0.0, 1e9, &v1::InbetweenParameters::set_tau},
        Bounded{"alpha", 0.0, 1.0, &v1::InbetweenParameters::set_alpha},
        Bounded{"epsilon", 0.0, 1e6, &v1::InbetweenParameters::set_epsilon},
        Bounded{"rho", 1e-9, 1e9, &v1::InbetweenParameters::set_rho},
        Bounded{"timestep", 1e-9, 10.0, &v1::InbetweenParameters::set_timestep}}) {
    if (!node.Has(b.key)) continue;
    PROJECT_ASSIGN_OR_RETURN(v, node.Child(b.key).Number(b.min, b.max));
    (out->*b.set)(v);
  }
  if (node.Has("max_iterations")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("max_iterations").Integer(1, 10000));
    out->set_max_iterations(static_cast<uint32_t>(v));
  }
  return absl::OkStatus();
}

absl::Status ParseImport(const Node& node, ImportSettings* out) {
  if (absl::Status s = node.CheckKeys({"gap_tolerance", "min_area_fraction"}); !s.ok()) return s;
  for (auto [key, value] : {std::pair{"gap_tolerance", &out->gap_tolerance},
                            std::pair{"min_area_fraction", &out->min_area_fraction}}) {
    if (!node.Has(key)) continue;
    PROJECT_ASSIGN_OR_RETURN(v, node.Child(key).Number(0.0, kMaxImportFraction));
    *value = v;
  }
  return absl::OkStatus();
}

absl::Status ParseOutput(const Node& node, OutputSettings* out) {
  if (absl::Status s = node.CheckKeys({"formats", "width", "fps", "fill", "mesh_overlay"});
      !s.ok()) {
    return s;
  }
  if (node.Has("formats")) {
    Node formats = node.Child("formats");
    if (absl::Status s = formats.Array(); !s.ok()) return s;
    out->formats.clear();
    for (size_t i = 0; i < formats.value().size(); ++i) {
      PROJECT_ASSIGN_OR_RETURN(f, formats.Item(i).String());
      out->formats.push_back(f);
    }
  }
  if (node.Has("width")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("width").Integer(8, 16384));
    out->width = static_cast<int>(v);
  }
  if (node.Has("fps")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("fps").Number(0.1, 240.0));
    out->fps = v;
  }
  if (node.Has("fill")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("fill").String());
    if (auto c = render::ParseColor(v); !c.ok())
      return node.Child("fill").Error(std::string(c.status().message()));
    out->fill = v;
  }
  if (node.Has("mesh_overlay")) {
    PROJECT_ASSIGN_OR_RETURN(v, node.Child("mesh_overlay").Bool());
    out->mesh_overlay = v;
  }
  return absl::OkStatus();
}

json PolylinesToJson(const std::vector<XYs>& lines) {
  json out = json::array();
  for (const XYs& line : lines) out.push_back(line);
  return out;
}

}  // namespace

absl::StatusOr<Project> ParseProject(const json& doc, const std::filesystem::path& base_dir) {
  Node root(doc, "$");
  if (absl::Status s = root.CheckKeys({"version", "drawings", "correspondences", "import",
                                       "meshing", "comesh", "inbetween", "output"});
      !s.ok()) {
    return s;
  }
  Project project;
  if (!root.Has("version")) return root.Error("missing field 'version' (use 1)");
  PROJECT_ASSIGN_OR_RETURN(version, root.Child("version").Integer(1, 1000));
  if (version != kProjectFileVersion) {
    return root.Child("version").Error(absl::StrCat(
        "unsupported version ", version, " (this tool reads version ", kProjectFileVersion, ")"));
  }
  if (!root.Has("drawings")) return root.Error("missing field 'drawings'");
  Node drawings = root.Child("drawings");
  if (absl::Status s = drawings.Array(); !s.ok()) return s;
  if (drawings.value().size() < 2 || drawings.value().size() > 16) {
    return drawings.Error(absl::StrCat("needs 2 to 16 drawings, has ", drawings.value().size()));
  }
  for (size_t i = 0; i < drawings.value().size(); ++i) {
    ProjectDrawing d;
    if (absl::Status s = ParseDrawing(drawings.Item(i), base_dir, &d); !s.ok()) return s;
    project.drawings.push_back(std::move(d));
  }
  size_t with_key_time = 0;
  std::vector<double> key_times;
  for (const ProjectDrawing& d : project.drawings) {
    if (d.key_time) ++with_key_time, key_times.push_back(*d.key_time);
  }
  if (with_key_time != 0) {
    if (with_key_time != project.drawings.size()) {
      return drawings.Error(absl::StrCat("key_time is set on ", with_key_time, " of ",
                                         project.drawings.size(),
                                         " drawings: set it on every drawing or on none"));
    }
    if (absl::Status s = CheckKeyTimes(key_times, project.drawings.size()); !s.ok()) {
      return drawings.Error(absl::StrCat("key_time: ", s.message()));
    }
  }
  if (root.Has("correspondences")) {
    Node marks = root.Child("correspondences");
    if (absl::Status s = marks.Array(); !s.ok()) return s;
    for (size_t i = 0; i < marks.value().size(); ++i) {
      PROJECT_ASSIGN_OR_RETURN(points, marks.Item(i).Polyline(project.drawings.size()));
      if (points.size() != project.drawings.size()) {
        return marks.Item(i).Error(absl::StrCat("needs one point per drawing (",
                                                project.drawings.size(), "), has ", points.size()));
      }
      project.correspondences.push_back(std::move(points));
    }
  }
  if (root.Has("import")) {
    absl::Status s = ParseImport(root.Child("import"), &project.import_settings);
    if (!s.ok()) return s;
  }
  if (root.Has("meshing")) {
    absl::Status s = ParseMeshing(root.Child("meshing"), project.parameters.mutable_meshing());
    if (!s.ok()) return s;
  }
  if (root.Has("comesh")) {
    absl::Status s = ParseComesh(root.Child("comesh"), project.parameters.mutable_comesh());
    if (!s.ok()) return s;
  }
  if (root.Has("inbetween")) {
    absl::Status s =
        ParseInbetween(root.Child("inbetween"), project.parameters.mutable_inbetween());
    if (!s.ok()) return s;
  }
  if (root.Has("output")) {
    if (absl::Status s = ParseOutput(root.Child("output"), &project.output); !s.ok()) return s;
  }
  return project;
}

std::optional<v1::TimingCurve> TimingCurveFromName(std::string_view name) {
  if (name == "linear") return v1::TIMING_CURVE_LINEAR;
  if (name == "catmull_rom" || name == "catmull-rom") return v1::TIMING_CURVE_CATMULL_ROM;
  if (name == "ease_in_out" || name == "ease-in-out") return v1::TIMING_CURVE_EASE_IN_OUT;
  return std::nullopt;
}

absl::Status CheckKeyTimes(const std::vector<double>& key_times, size_t drawings) {
  if (key_times.size() != drawings) {
    return absl::InvalidArgumentError(
        absl::StrCat("needs one time per drawing (", drawings, "), has ", key_times.size()));
  }
  for (size_t i = 0; i < key_times.size(); ++i) {
    const double t = key_times[i];
    if (!std::isfinite(t) || t < 0 || t > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("time ", t, " of drawing ", i + 1, " is not in [0, 1]"));
    }
    if (i > 0 && !(t > key_times[i - 1])) {
      return absl::InvalidArgumentError(absl::StrCat("times must increase strictly: drawing ",
                                                     i + 1, " has ", t, " after ",
                                                     key_times[i - 1]));
    }
  }
  if (key_times.front() != 0.0 || key_times.back() != 1.0) {
    return absl::InvalidArgumentError(absl::StrCat("the first time must be 0 and the last 1, got ",
                                                   key_times.front(), " and ", key_times.back()));
  }
  return absl::OkStatus();
}

absl::StatusOr<Project> LoadProject(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return absl::NotFoundError(absl::StrCat(path.string(), ": cannot open"));
  json doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) {
    return absl::InvalidArgumentError(absl::StrCat(path.string(), ": not valid JSON"));
  }
  auto project = ParseProject(doc, path.parent_path());
  if (!project.ok()) {
    return absl::Status(project.status().code(),
                        absl::StrCat(path.string(), ": ", project.status().message()));
  }
  return project;
}

json ProjectToJson(const Project& project, const std::filesystem::path& base_dir) {
  json drawings = json::array();
  for (const ProjectDrawing& d : project.drawings) {
    std::error_code ec;
    std::filesystem::path rel = std::filesystem::relative(d.file, base_dir, ec);
    json item = {{"file", (ec || rel.empty() ? d.file : rel).generic_string()}};
    if (d.key_time) item["key_time"] = *d.key_time;
    if (!d.cuts.empty()) item["cuts"] = PolylinesToJson(d.cuts);
    if (!d.openings.empty()) item["openings"] = PolylinesToJson(d.openings);
    drawings.push_back(std::move(item));
  }
  json doc = {{"version", project.version}, {"drawings", std::move(drawings)}};
  if (!project.correspondences.empty()) {
    doc["correspondences"] = PolylinesToJson(project.correspondences);
  }
  json import_settings = json::object();
  if (project.import_settings.gap_tolerance) {
    import_settings["gap_tolerance"] = *project.import_settings.gap_tolerance;
  }
  if (project.import_settings.min_area_fraction) {
    import_settings["min_area_fraction"] = *project.import_settings.min_area_fraction;
  }
  if (!import_settings.empty()) doc["import"] = std::move(import_settings);
  const v1::MeshingParameters& m = project.parameters.meshing();
  json meshing = json::object();
  if (m.boundary_vertices()) meshing["boundary_vertices"] = m.boundary_vertices();
  if (m.max_edge_relative() > 0) meshing["max_edge_relative"] = m.max_edge_relative();
  if (m.shape_bound() > 0) meshing["shape_bound"] = m.shape_bound();
  if (m.corner_matching() != v1::CORNER_MATCHING_UNSPECIFIED &&
      v1::CornerMatching_IsValid(m.corner_matching())) {
    meshing["corner_matching"] = kCornerMatchings[m.corner_matching()];
  }
  if (m.has_boundary_tolerance()) meshing["boundary_tolerance"] = m.boundary_tolerance();
  if (m.boundary_alignment() != v1::BOUNDARY_ALIGNMENT_UNSPECIFIED &&
      v1::BoundaryAlignment_IsValid(m.boundary_alignment())) {
    meshing["boundary_alignment"] = kBoundaryAlignments[m.boundary_alignment()];
  }
  if (!meshing.empty()) doc["meshing"] = std::move(meshing);
  const v1::ComeshParameters& c = project.parameters.comesh();
  json comesh = json::object();
  if (c.has_map_weight()) comesh["map_weight"] = c.map_weight();
  if (c.max_outer_iterations()) comesh["max_outer_iterations"] = c.max_outer_iterations();
  if (c.max_inner_iterations()) comesh["max_inner_iterations"] = c.max_inner_iterations();
  if (c.tolerance() > 0) comesh["tolerance"] = c.tolerance();
  if (c.has_outer_tolerance()) comesh["outer_tolerance"] = c.outer_tolerance();
  if (c.has_min_quality()) comesh["min_quality"] = c.min_quality();
  if (c.has_slide_window()) comesh["slide_window"] = c.slide_window();
  if (c.has_outline_corner_degrees()) {
    comesh["outline_corner_degrees"] = c.outline_corner_degrees();
  }
  if (!comesh.empty()) doc["comesh"] = std::move(comesh);
  const v1::InbetweenParameters& p = project.parameters.inbetween();
  json inbetween = json::object();
  static const char* kMethods[] = {"zhu17", "linear", "alexa", "zhu17"};
  static const char* kCurves[] = {"linear", "linear", "catmull_rom", "ease_in_out"};
  if (p.method() != v1::METHOD_UNSPECIFIED) inbetween["method"] = kMethods[p.method()];
  if (p.frames()) inbetween["frames"] = p.frames();
  if (p.timing() != v1::TIMING_CURVE_UNSPECIFIED) inbetween["timing"] = kCurves[p.timing()];
  if (p.ease_size()) inbetween["ease"] = std::vector<double>(p.ease().begin(), p.ease().end());
  if (p.stiffness_size()) {
    json regions = json::array();
    for (const auto& r : p.stiffness()) {
      XYs polygon;
      for (const auto& q : r.polygon().points()) polygon.push_back({q.x(), q.y()});
      regions.push_back({{"polygon", polygon}, {"kappa", r.kappa()}});
    }
    inbetween["stiffness"] = std::move(regions);
  }
  if (p.has_lambda()) inbetween["lambda"] = p.lambda();
  if (p.has_tau()) inbetween["tau"] = p.tau();
  if (p.has_alpha()) inbetween["alpha"] = p.alpha();
  if (p.epsilon() > 0) inbetween["epsilon"] = p.epsilon();
  if (p.has_rho()) inbetween["rho"] = p.rho();
  if (p.has_timestep()) inbetween["timestep"] = p.timestep();
  if (p.max_iterations()) inbetween["max_iterations"] = p.max_iterations();
  if (!inbetween.empty()) doc["inbetween"] = std::move(inbetween);
  doc["output"] = {{"formats", project.output.formats},
                   {"width", project.output.width},
                   {"fps", project.output.fps},
                   {"mesh_overlay", project.output.mesh_overlay}};
  if (project.output.fill) doc["output"]["fill"] = *project.output.fill;
  return doc;
}

}  // namespace inbetween::client
