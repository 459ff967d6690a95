// Inbetweening speed: frames per second of kZhu17 and kAlexa for 2 and 16 examples on
// generated 4 x 1 bars of ~1.6k, 10k and 50k vertices, iterations per frame, the floor
// iteration (one prefactored 2-RHS solve + one local step, measured in the same run) and peak
// memory, and the accuracy of the default stopping rule: the largest vertex distance (relative to
// the bar's length) between a frame and the same frame solved to tight convergence, at 1/4, 1/2
// and 3/4 of the sequence. Usage:
//   inbetween [--json FILE] [--min-vertices N] [--max-vertices N] [--trust R] [--tolerance T]
//             [--no-anderson] [--threads N]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "nlohmann/json.hpp"
#include "solver/core/sparse_cholesky.h"
#include "solver/interp/blended_arap.h"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"
#include "tests/unit/solver/interp/test_meshes.h"

namespace {

using namespace inbetween::solver;  // NOLINT(build/namespaces): a benchmark program
using Clock = std::chrono::steady_clock;

double PeakMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// A 4 x 1 bar (cells x cells/4) and `examples` keys: straight, then bends about the centre line
// alternating in direction with growing angle (2 examples: straight and curled 270 degrees).
Multimesh Bar(int cells, int examples) {
  Multimesh mesh = interp_test::GridMesh(cells, cells / 4, 4.0 / cells);
  for (int i = 1; i < examples; ++i) {
    const double angle =
        examples == 2 ? 1.5 * std::numbers::pi
                      : (i % 2 == 0 ? 1.0 : -1.0) * (0.4 + 1.1 * i / examples) * std::numbers::pi;
    mesh.shapes.push_back(interp_test::BentAboutCentre(mesh.shapes[0], 4.0, angle));
  }
  return mesh;
}

// Runs f() in a forked child and returns its value (-1 on failure).
template <class F>
double InChild(F&& f) {
  int fds[2];
  if (pipe(fds) != 0) return -1.0;
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const double value = f();
    const ssize_t written = write(fds[1], &value, sizeof(value));
    _exit(written == sizeof(value) ? 0 : 1);
  }
  close(fds[1]);
  double value = -1.0;
  if (pid < 0 || read(fds[0], &value, sizeof(value)) != sizeof(value)) value = -1.0;
  close(fds[0]);
  if (pid > 0) waitpid(pid, nullptr, 0);
  return value;
}

double FloorMicroseconds(const Multimesh& mesh) {
  absl::StatusOr<BlendedArap> arap = BlendedArap::Create(mesh.triangles, mesh.shapes);
  if (!arap.ok()) return -1;
  // Pin vertex 0 (one component), as the solver does.
  const Eigen::SparseMatrix<double> k =
      arap->Laplacian().bottomRightCorner(mesh.num_vertices() - 1, mesh.num_vertices() - 1);
  Eigen::SparseMatrix<double> kc = k;
  kc.makeCompressed();
  SparseCholesky solver;
  if (!solver.Compute(kc).ok()) return -1;
  std::vector<double> w(mesh.num_shapes(), 0.0);
  w[0] = w[1] = 0.5;
  Coords x = ToCoords(mesh.shapes[1]);
  std::vector<Eigen::Matrix2d> targets;
  Coords b = Coords::Zero(mesh.num_vertices(), 2);
  const int reps = mesh.num_vertices() > 20000 ? 20 : 100;
  const auto start = Clock::now();
  for (int r = 0; r < reps; ++r) {
    arap->LocalStep(x, w, &targets);
    b.setZero();
    arap->AddRhs(targets, &b);
    absl::StatusOr<Eigen::MatrixXd> sol = solver.Solve(b.bottomRows(mesh.num_vertices() - 1));
    x.bottomRows(mesh.num_vertices() - 1) = *sol;
  }
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count() / reps;
}

}  // namespace

int main(int argc, char** argv) {
  std::string json_path;
  int max_vertices = 60000;
  int min_vertices = 0;
  InbetweenOptions defaults;
  for (int a = 1; a < argc; ++a) {
    if (!std::strcmp(argv[a], "--json") && a + 1 < argc) json_path = argv[++a];
    if (!std::strcmp(argv[a], "--max-vertices") && a + 1 < argc)
      max_vertices = std::atoi(argv[++a]);
    if (!std::strcmp(argv[a], "--min-vertices") && a + 1 < argc)
      min_vertices = std::atoi(argv[++a]);
    if (!std::strcmp(argv[a], "--trust") && a + 1 < argc)
      defaults.warm_start_trust_radius = std::atof(argv[++a]);
    if (!std::strcmp(argv[a], "--tolerance") && a + 1 < argc)
      defaults.displacement_tolerance = std::atof(argv[++a]);
    if (!std::strcmp(argv[a], "--no-anderson")) defaults.anderson = false;
    if (!std::strcmp(argv[a], "--threads") && a + 1 < argc) defaults.threads = std::atoi(argv[++a]);
  }
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%-7s %8s %9s %7s %9s %9s %9s %11s %9s %8s\n", "method", "examples", "vertices",
              "frames", "frames/s", "it/frame", "floor_us", "frame/floor", "max_error", "peak_MB");
  for (int cells : {80, 200, 448}) {
    for (int examples : {2, 16}) {
      const Multimesh mesh = Bar(cells, examples);
      if (mesh.num_vertices() > max_vertices || mesh.num_vertices() < min_vertices) continue;
      const double floor_us = FloorMicroseconds(mesh);
      const int frames = (examples - 1) * 24 + 1;  // 24 frames per key pair
      absl::StatusOr<Schedule> schedule = MakeSchedule(examples, frames);
      for (InterpMethod method : {InterpMethod::kZhu17, InterpMethod::kAlexa}) {
        InbetweenOptions o = defaults;
        o.method = method;
        absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, o);
        if (!ib.ok()) {
          std::fprintf(stderr, "%s\n", std::string(ib.status().message()).c_str());
          return 1;
        }
        Frame previous;
        long iterations = 0;
        int inverted = 0;
        const std::vector<int> probes = {frames / 4, frames / 2, 3 * frames / 4};
        std::vector<Frame> probed;
        const auto start = Clock::now();
        for (int k = 0; k < frames; ++k) {
          FrameReport report;
          absl::StatusOr<Frame> f =
              ib->Solve(schedule->frames[k].weights, previous, nullptr, &report);
          if (!f.ok()) return 1;
          iterations += report.iterations;
          inverted += report.inverted;
          previous = *std::move(f);
          if (std::find(probes.begin(), probes.end(), k) != probes.end())
            probed.push_back(previous);
        }
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        const double peak_mb = PeakMb();
        // Accuracy (zhu17): each probed frame against a tight solve started from it, in a child
        // process so that the reference solver does not count in this process's peak memory.
        double max_error = 0.0;
        if (method == InterpMethod::kZhu17) {
          max_error = InChild([&] {
            InbetweenOptions tight = o;
            tight.max_iterations = 3000;
            tight.displacement_tolerance = 1e-10;
            tight.convergence_tolerance = 0.0;
            absl::StatusOr<Inbetweener> reference = Inbetweener::Create(mesh, tight);
            if (!reference.ok()) return -1.0;
            double error = 0.0;
            for (size_t q = 0; q < probes.size(); ++q) {
              absl::StatusOr<Frame> f =
                  reference->Solve(schedule->frames[probes[q]].weights, probed[q]);
              if (!f.ok()) return -1.0;
              for (int v = 0; v < mesh.num_vertices(); ++v) {
                error = std::max(error, (f->vertices[v] - probed[q].vertices[v]).norm() / 4.0);
              }
            }
            return error;
          });
        }
        const double fps = frames / seconds;
        const char* name = method == InterpMethod::kZhu17 ? "zhu17" : "alexa";
        const double per_frame_us = 1e6 / fps;
        std::printf("%-7s %8d %9d %7d %9.1f %9.2f %9.1f %11.2f %9.1e %8.1f\n", name, examples,
                    mesh.num_vertices(), frames, fps, static_cast<double>(iterations) / frames,
                    floor_us, per_frame_us / floor_us, max_error, peak_mb);
        rows.push_back({{"method", name},
                        {"examples", examples},
                        {"vertices", mesh.num_vertices()},
                        {"frames_per_second", fps},
                        {"iterations_per_frame", static_cast<double>(iterations) / frames},
                        {"floor_iteration_us", floor_us},
                        {"peak_mb", peak_mb},
                        {"max_relative_error", max_error},
                        {"inverted_triangles", inverted}});
      }
    }
  }
  if (!json_path.empty()) std::ofstream(json_path) << rows.dump(2) << "\n";
  return 0;
}
