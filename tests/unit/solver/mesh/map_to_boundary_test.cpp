// Tests for the injective mapping: convex (Tutte) and non-convex (barrier) targets land exactly
// on the boundary with no inverted triangle; impossible targets fail instead of folding.
#include "solver/mesh/map_to_boundary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

#include "absl/strings/match.h"
#include "solver/geometry/correspondence.h"
#include "solver/geometry/polygon.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/split_boundary_chords.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/core/address_space.h"

namespace inbetween::solver {
namespace {

using testing::AddressSpaceBytes;
using testing::kSanitizerBuild;

Points Square() { return {{0, 0}, {100, 0}, {100, 100}, {0, 100}}; }

Points Hexagon() {
  Points p;
  for (int i = 0; i < 6; ++i)
    p.emplace_back(60 + 55 * std::cos(i * M_PI / 3), 60 + 55 * std::sin(i * M_PI / 3));
  return p;
}

Points Bar() { return {{0, 0}, {141.4, 0}, {141.4, 30}, {0, 30}}; }

// Annulus sector of `turns` * 180 degrees, radii 30 and 60, positive orientation.
Points Arch(double turns = 1.0) {
  Points p;
  const int k = static_cast<int>(40 * turns);
  for (int i = 0; i <= k; ++i) {
    const double a = turns * M_PI * i / k;
    p.emplace_back(80 - 60 * std::cos(a), 100 - 60 * std::sin(a));
  }
  for (int i = k; i >= 0; --i) {
    const double a = turns * M_PI * i / k;
    p.emplace_back(80 - 30 * std::cos(a), 100 - 30 * std::sin(a));
  }
  if (PolygonSignedArea(p) < 0) std::reverse(p.begin(), p.end());
  return p;
}

struct MapCase {
  Points source;
  std::vector<Triangle> triangles;
  std::vector<int> boundary;
  Points target;
};

// Mesh of the first outline, boundary target from the second (no boundary Steiner points: the
// size bound, none or `max_edge`, is generous relative to the boundary spacing).
MapCase Make(const Points& from, const Points& to, int n, double max_edge = 0.0) {
  CorrespondenceOptions c;
  c.vertices = n;
  absl::StatusOr<Correspondence> corr =
      ComputeCorrespondence({Drawing{{Outline{from}}}, Drawing{{Outline{to}}}}, c);
  EXPECT_TRUE(corr.ok()) << corr.status();
  TriangulateOptions mesh_options;
  mesh_options.max_edge = max_edge;
  absl::StatusOr<PolygonTriangulation> tri = CgalTriangulate(corr->boundaries[0], mesh_options);
  EXPECT_TRUE(tri.ok()) << tri.status();
  EXPECT_TRUE(tri->boundary_steiner.empty());
  MapCase s;
  s.source = tri->vertices;
  s.triangles = tri->triangles;
  std::vector<bool> is_boundary(s.source.size(), false);
  for (int i = 0; i < n; ++i) s.boundary.push_back(i), is_boundary[i] = true;
  SplitBoundaryChords(&s.source, &s.triangles, &is_boundary);
  s.target = corr->boundaries[1];
  return s;
}

void ExpectInjectiveAndExact(const MapCase& s, const Points& x) {
  EXPECT_EQ(CountInverted(s.triangles, x), 0);
  for (size_t k = 0; k < s.boundary.size(); ++k) EXPECT_EQ(x[s.boundary[k]], s.target[k]);
}

TEST(MapToBoundaryTest, SquareToHexagonUsesTutte) {
  const MapCase s = Make(Square(), Hexagon(), 64);
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_TRUE(report.tutte);
  EXPECT_GE(report.energy, 4.0);
}

TEST(MapToBoundaryTest, BarToArchNonConvexTutteStart) {
  const MapCase s = Make(Bar(), Arch(), 96);
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_TRUE(report.tutte);  // the mean-value embedding folds nothing here: no pull needed
  EXPECT_EQ(report.stages, 0);
  EXPECT_LT(report.energy, 10.0);
}

TEST(MapToBoundaryTest, BarToArchNonConvex) {
  const MapCase s = Make(Bar(), Arch(), 96);
  MapToBoundaryReport report;
  MapToBoundaryOptions options;
  options.tutte_first_always = false;  // the progressive pull on its own
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, options, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_FALSE(report.tutte);
  EXPECT_GT(report.stages, 0);
  EXPECT_LT(report.energy, 10.0);  // bending a bar is a mild distortion
}

TEST(MapToBoundaryTest, LongBarToThreeQuarterRing) {
  // Mid-line length of a 270-degree sector: 1.5 * pi * 45 ~ 212.
  const Points bar = {{0, 0}, {212, 0}, {212, 30}, {0, 30}};
  const MapCase s = Make(bar, Arch(1.5), 128);
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_LT(report.energy, 50.0);  // stronger bending than the half ring
}

TEST(MapToBoundaryTest, ArchToBarNonConvexSource) {
  const MapCase s = Make(Arch(), Bar(), 96);
  absl::StatusOr<Points> x = MapToBoundary(s.source, s.triangles, s.boundary, s.target);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
}

TEST(MapToBoundaryTest, AffineImageStartsFromTheAffineMap) {
  // A non-convex arch onto a rotated, sheared, scaled copy of itself: the pull starts from the
  // least-squares affine fit of the boundaries, which is exact here, so no stage is needed and
  // every vertex lands where the affine map puts it.
  MapCase s = Make(Arch(), Arch(), 96);
  Eigen::Matrix2d map;
  map << 1.2 * std::cos(0.7), -std::sin(0.7), 0.3 + std::sin(0.7), 0.8 * std::cos(0.7);
  ASSERT_GT(map.determinant(), 0.0);
  auto affine = [&](const Point& p) { return Point(map * p + Point(40, -25)); };
  for (size_t k = 0; k < s.boundary.size(); ++k) s.target[k] = affine(s.source[s.boundary[k]]);
  MapToBoundaryOptions options;
  options.tutte_first_always = false;
  MapToBoundaryReport report;
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, options, nullptr, &report);
  ASSERT_TRUE(x.ok()) << x.status();
  ExpectInjectiveAndExact(s, *x);
  EXPECT_FALSE(report.tutte);
  EXPECT_EQ(report.stages, 0);
  for (size_t v = 0; v < s.source.size(); ++v) {
    EXPECT_LT(((*x)[v] - affine(s.source[v])).norm(), 1e-6) << v;
  }
}

TEST(MapToBoundaryTest, ImpossibleTargetFailsWithoutFolding) {
  MapCase s = Make(Square(), Hexagon(), 32);
  std::reverse(s.target.begin() + 1, s.target.end());  // mirror: would need every triangle flipped
  MapToBoundaryOptions options;
  options.max_iterations = 150;
  absl::StatusOr<Points> x = MapToBoundary(s.source, s.triangles, s.boundary, s.target, options);
  ASSERT_FALSE(x.ok());
  EXPECT_EQ(x.status().code(), absl::StatusCode::kFailedPrecondition);
}

TEST(MapToBoundaryTest, Cancelled) {
  const MapCase s = Make(Bar(), Arch(), 48);
  CancelToken cancel;
  cancel.Cancel();
  absl::StatusOr<Points> x =
      MapToBoundary(s.source, s.triangles, s.boundary, s.target, {}, &cancel);
  EXPECT_EQ(x.status().code(), absl::StatusCode::kCancelled);
}

// Out of memory: MapToBoundary in a forked child whose address space is capped (RLIMIT_AS) a
// little above what it maps already, for a range of caps, so that allocations fail at many
// different points (the sparse factorizations among them). Eigen's SparseLU / SimplicialLDLT
// died there (a double free after a failed allocation, docs/hardening.md); the map must answer
// RESOURCE_EXHAUSTED "... out of memory ..." or succeed, never die.
// Not in sanitizer builds (address_space.h).
struct CappedRun {
  int exit = -1;        // 0 mapped, 1 RESOURCE_EXHAUSTED naming "out of memory", 2 another status,
                        // 5 an exception escaped; 128 + signal when the child died
  std::string message;  // the status message (first 300 bytes)
};

CappedRun MapUnderCap(const MapCase& s, const MapToBoundaryOptions& options, size_t headroom) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const size_t now = AddressSpaceBytes();
    rlimit cap;
    cap.rlim_cur = cap.rlim_max = now + headroom;
    if (now == 0 || setrlimit(RLIMIT_AS, &cap) != 0) _exit(3);
    absl::StatusOr<Points> x = absl::UnknownError("not run");
    try {
      x = MapToBoundary(s.source, s.triangles, s.boundary, s.target, options);
    } catch (...) {
      _exit(5);  // not into gtest's handler: the child must not go on running tests
    }
    char text[300] = {};
    int code = 0;
    if (!x.ok()) {
      const absl::Status& st = x.status();
      code =
          absl::IsResourceExhausted(st) && absl::StrContains(st.message(), "out of memory") ? 1 : 2;
      std::snprintf(text, sizeof(text), "%s", st.ToString().c_str());
    }
    if (write(fds[1], text, sizeof(text)) < 0) _exit(4);
    _exit(code);  // no destructors, no gtest in the child
  }
  close(fds[1]);
  CappedRun run;
  char text[300] = {};
  if (read(fds[0], text, sizeof(text)) > 0) run.message.assign(text, strnlen(text, sizeof(text)));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  run.exit = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return run;
}

// Caps from 1 MiB above the child's address space up, 1.15x apart, until two runs in a row map
// (at most 512 MiB): every run maps or answers out of memory, the tightest run out, and some
// run out in `factorizing` (the named sparse system), not only in the vectors around it.
void ExpectOutOfMemoryIsAStatus(const MapCase& s, const MapToBoundaryOptions& options,
                                const std::string& factorizing) {
  int out_of_memory = 0, mapped = 0, named = 0, last = -1, mapped_in_a_row = 0;
  for (double headroom = 1 << 20; headroom < (512 << 20) && mapped_in_a_row < 2; headroom *= 1.15) {
    const CappedRun run = MapUnderCap(s, options, static_cast<size_t>(headroom));
    EXPECT_TRUE(run.exit == 0 || run.exit == 1) << "cap +" << static_cast<long>(headroom / 1024)
                                                << " KiB: exit " << run.exit << " " << run.message;
    out_of_memory += run.exit == 1;
    mapped += run.exit == 0;
    named += run.exit == 1 && absl::StrContains(run.message, factorizing);
    if (run.exit == 1) std::printf("cap +%.0f KiB: %s\n", headroom / 1024, run.message.c_str());
    last = run.exit;
    mapped_in_a_row = run.exit == 0 ? mapped_in_a_row + 1 : 0;
  }
  EXPECT_GT(out_of_memory, 0);
  EXPECT_GT(mapped, 0);
  EXPECT_EQ(last, 0);
  EXPECT_GT(named, 0) << "no cap ran out in " << factorizing;
}

TEST(MapToBoundaryTest, OutOfMemoryInTheTutteSystemIsAStatus) {
  if (kSanitizerBuild) GTEST_SKIP() << "RLIMIT_AS caps do not apply under ASan/TSan";
  const MapCase s = Make(Square(), Hexagon(), 400, 1.5);
  std::printf("%zu vertices, %zu triangles\n", s.source.size(), s.triangles.size());
  ExpectOutOfMemoryIsAStatus(s, {}, "Tutte system");
}

TEST(MapToBoundaryTest, OutOfMemoryInTheProxySystemIsAStatus) {
  if (kSanitizerBuild) GTEST_SKIP() << "RLIMIT_AS caps do not apply under ASan/TSan";
  const MapCase s = Make(Bar(), Arch(), 400, 2.0);
  std::printf("%zu vertices, %zu triangles\n", s.source.size(), s.triangles.size());
  MapToBoundaryOptions options;
  options.tutte_first_always = false;  // the progressive pull: SLIM proxy solves only
  ExpectOutOfMemoryIsAStatus(s, options, "SLIM proxy system");
}

}  // namespace
}  // namespace inbetween::solver
