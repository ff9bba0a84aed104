#include "reproduce_command.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/core/fairing_study.hpp"
#include "posefair/core/quaternion_spline_example.hpp"
#include "posefair/core/quaternion_spline_study.hpp"
#include "posefair/core/sphere_spline_figure6.hpp"

namespace posefair::tools {
namespace {

struct Run {
  const char* name;
  int order;
  double lambda_r;
  OperatorVariant variant;
  bool figures_4_to_8 = false;  // the perturbation of Figs. 4–8 (0.2 rad, 20 mm), not Section 6's
};

// Figures 2–5 of the paper: m = 2 vs 3 at λ_r = 0.1; λ_r = 0.1/0.2/0.3 for m = 3 (and m = 2);
// the printed operators beside the corrected ones; and Figs. 4–5 on their own setup.
constexpr Run kRuns[] = {
    {"m2-l0.1", 2, 0.1, OperatorVariant::Corrected}, {"m2-l0.2", 2, 0.2, OperatorVariant::Corrected},
    {"m2-l0.3", 2, 0.3, OperatorVariant::Corrected}, {"m3-l0.1", 3, 0.1, OperatorVariant::Corrected},
    {"m3-l0.2", 3, 0.2, OperatorVariant::Corrected}, {"m3-l0.3", 3, 0.3, OperatorVariant::Corrected},
    {"m2-l0.1-printed", 2, 0.1, OperatorVariant::Printed}, {"m3-l0.1-printed", 3, 0.1, OperatorVariant::Printed},
    {"m3-l0.1-fig4-8", 3, 0.1, OperatorVariant::Corrected, true},
};

// Section 6: ‖δ_r‖ < 0.1, ‖δ_t‖ < 10 mm. Figures 4–8: "within 0.2 (radians) … and 20 (mm)".
SyntheticMotionSpec section6_spec() { return {}; }
SyntheticMotionSpec figures_4_to_8_spec() {
  SyntheticMotionSpec s;
  s.rotation_noise = 0.2;
  s.position_noise = 20.0;
  return s;
}

std::filesystem::path beside(const std::filesystem::path& out, const std::string& suffix) {
  return out.parent_path() / (out.stem().string() + "-" + suffix + ".csv");
}

// Closes a table and says where it went, or why it failed (exit status 73).
int finish_csv(std::ofstream& f, const std::filesystem::path& out) {
  f.close();
  if (!f) {
    std::cerr << "posefair reproduce: writing " << out << " failed\n";
    return exit_code(ErrorKind::CantCreate);
  }
  std::printf("wrote %s\n", out.c_str());
  return kExitOk;
}

std::ofstream open_csv(const std::filesystem::path& path, const char* header) {
  std::ofstream f(path);
  if (f) f << header << "\n";
  return f;
}

// Fig. 1's loop with ε at the perturbation bound, positions and orientations together, and
// each bound alone (to see which one stops it).
bool bound_table(const std::filesystem::path& path, int seeds) {
  std::ofstream f = open_csv(path, "setup,order,bounds,seed,iterations,stop,breaking_rotation,breaking_position,first_breaking");
  if (!f) return false;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::printf("\nFig. 1 loop at the perturbation bound (lambda_t 0.5, lambda_r 0.1; sweeps kept per seed):\n");
  for (const bool fig : {false, true}) {
    const SyntheticMotionSpec spec = fig ? figures_4_to_8_spec() : section6_spec();
    const char* setup = fig ? "figs4-8" : "section6";
    for (int order : {2, 3}) {
      for (const char* bounds : {"both", "rotation", "position"}) {
        FairingParams p;
        p.order = order;
        p.max_iterations = 100000;
        const bool rot = bounds[0] != 'p', pos = bounds[0] != 'r';
        p.epsilon_r = rot ? spec.rotation_noise : kInf;
        p.epsilon_t = pos ? spec.position_noise : kInf;
        const auto runs = bounded_runs(spec, seeds, p);
        std::printf("  %-8s m=%d eps %-8s:", setup, order, bounds);
        for (const auto& r : runs) {
          std::printf(" %4d", r.iterations);
          f << setup << ',' << order << ',' << bounds << ',' << r.seed << ',' << r.iterations << ','
            << to_string(r.stop) << ',' << r.breaking_rotation << ',' << r.breaking_position << ','
            << r.first_breaking << '\n';
        }
        std::printf("   (next sweep breaks it at sample");
        for (const auto& r : runs) std::printf(" %td", r.first_breaking);
        std::printf(")\n");
      }
    }
  }
  return static_cast<bool>(f);
}

// Claim (a) on motions of different curvature: the number of slow oscillations over the
// 100 samples, 0.25 to 4 (Section 6's data: 1).
bool curvature_table(const std::filesystem::path& path, int seeds, int iterations) {
  std::ofstream f = open_csv(path, "cycles,truth_angular_acceleration,order,iteration,mean_error_to_input,mean_error_to_truth");
  if (!f) return false;
  std::printf("\nClaim (a) by curvature (Section 6 noise, lambda_r 0.1, mean of %d seeds; error to input / to truth):\n", seeds);
  for (double cycles : {0.25, 0.5, 1.0, 2.0, 4.0}) {
    SyntheticMotionSpec spec = section6_spec();
    spec.cycles = cycles;
    double curvature = 0.0;
    for (int s = 1; s <= seeds; ++s) {
      spec.seed = static_cast<std::uint64_t>(s);
      curvature += mean_angular_acceleration(make_synthetic_motion(spec).truth) / seeds;
    }
    std::printf("  cycles %4.2f (truth %6.1f rad/s2):", cycles, curvature);
    for (int order : {2, 3}) {
      FairingParams p;
      p.order = order;
      p.max_iterations = iterations;
      const auto t = mean_trace(spec, seeds, p);
      const int early = std::min(100, iterations);
      for (int k : {early, iterations}) {
        f << cycles << ',' << curvature << ',' << order << ',' << k << ',' << t[k].mean_error_to_input << ','
          << t[k].mean_error_to_truth << '\n';
      }
      std::printf("  m=%d @%d %.4f/%.4f @%d %.4f/%.4f", order, early, t[early].mean_error_to_input,
                  t[early].mean_error_to_truth, iterations, t[iterations].mean_error_to_input,
                  t[iterations].mean_error_to_truth);
    }
    std::printf("\n");
  }
  return static_cast<bool>(f);
}

// Figures 6–8: one motion of the Figs. 4–8 setup, m = 3, 100 sweeps, without a bound.
bool motion_table(const std::filesystem::path& path) {
  std::ofstream f = open_csv(path, "stage,i,t,px,py,pz,qw,qx,qy,qz");
  if (!f) return false;
  FairingParams p;
  p.order = 3;
  p.max_iterations = 100;
  const auto st = faired_motion_stages(figures_4_to_8_spec(), p);
  const std::pair<const char*, const PoseSequence*> stages[] = {
      {"truth", &st.truth}, {"noisy", &st.noisy}, {"translation", &st.translation_faired}, {"faired", &st.faired}};
  for (const auto& [name, s] : stages) {
    for (std::size_t i = 0; i < s->size(); ++i) {
      const Quat& q = s->orientation[i];
      const Vec3& x = s->position[i];
      char line[256];
      std::snprintf(line, sizeof line, "%s,%zu,%.4f,%.9g,%.9g,%.9g,%.12g,%.12g,%.12g,%.12g\n", name, i, s->time[i], x.x(),
                    x.y(), x.z(), q.w(), q.x(), q.y(), q.z());
      f << line;
    }
  }
  return static_cast<bool>(f);
}

int reproduce_lee_shin(const std::filesystem::path& out, int iterations, int seeds) {
  std::ofstream f(out);
  if (!f) {
    std::cerr << "posefair reproduce: cannot write " << out << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  f << "run,order,lambda_r,variant,iteration,mean_error_to_input,mean_error_to_truth,max_error_to_input,"
       "mean_angular_acceleration,mean_position_error_to_truth,mean_acceleration,rotational_energy\n";
  for (const Run& run : kRuns) {
    FairingParams p;
    p.order = run.order;
    p.lambda_r = run.lambda_r;
    p.variant = run.variant;
    p.max_iterations = iterations;
    const auto trace = mean_trace(run.figures_4_to_8 ? figures_4_to_8_spec() : section6_spec(), seeds, p);
    for (const auto& t : trace) {
      char line[512];
      std::snprintf(line, sizeof line, "%s,%d,%.2f,%s,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", run.name, run.order,
                    run.lambda_r, run.variant == OperatorVariant::Printed ? "printed" : "corrected", t.iteration,
                    t.mean_error_to_input, t.mean_error_to_truth, t.max_error_to_input, t.mean_angular_acceleration,
                    t.mean_position_error_to_truth, t.mean_acceleration, t.rotational_energy);
      f << line;
    }
    const auto& last = trace.back();
    std::printf("%-16s after %4d sweeps: mean error to input %.4f, to truth %.4f (input %.4f) rad on S3\n", run.name,
                last.iteration, last.mean_error_to_input, last.mean_error_to_truth, trace.front().mean_error_to_truth);
    if (run.figures_4_to_8 && trace.size() > 100) {
      std::printf("%-16s angular acceleration %.0f -> %.0f (10 sweeps) -> %.0f (100) rad/s2; "
                  "acceleration %.0f -> %.0f -> %.0f mm/s2\n", "", trace[0].mean_angular_acceleration,
                  trace[10].mean_angular_acceleration, trace[100].mean_angular_acceleration, trace[0].mean_acceleration,
                  trace[10].mean_acceleration, trace[100].mean_acceleration);
    }
  }
  f.close();
  const auto bound = beside(out, "bound"), curvature = beside(out, "curvature"), motion = beside(out, "motion");
  if (!f || !bound_table(bound, seeds) || !curvature_table(curvature, seeds, iterations) || !motion_table(motion)) {
    std::cerr << "posefair reproduce: writing " << out << " or the tables beside it failed\n";
    return exit_code(ErrorKind::CantCreate);
  }
  std::printf("wrote %s, %s, %s, %s\n", out.c_str(), bound.c_str(), curvature.c_str(), motion.c_str());
  return kExitOk;
}

// Ramamoorthi & Barr Section 4 on the documented example and on seeded random key sets of the
// same kind: the 4-frame gap to the optimum and the norm deviation, each set and their spread.
int reproduce_ramamoorthi_barr(const std::filesystem::path& out, int seeds) {
  std::ofstream f = open_csv(out, "family,keys,optimum,gap_4,gap_8,gap_24,max_norm_deviation_4,mean_norm_deviation_4");
  if (!f) {
    std::cerr << "posefair reproduce: cannot write " << out << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  auto spread = [](std::vector<double> v, double scale) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    char text[96];
    std::snprintf(text, sizeof text, "%.3g / %.3g / %.3g", scale * v.front(), scale * median, scale * v.back());
    return std::string(text);
  };
  auto row = [&](const char* family, const std::string& name, const KeySetClaims& c) {
    std::printf("%-10s %9.5f   %8.3f%%   %7.3f%%  %8.4f%%   %9.3f%%   %10.4f%%   %7.3f\n", name.c_str(), c.optimum,
                100 * c.gap_4, 100 * c.gap_8, 100 * c.gap_24, 100 * c.max_norm_deviation_4, 100 * c.mean_norm_deviation_4,
                c.mean_norm_deviation_4 / c.max_norm_deviation_4);
    f << family << ',' << name << ',' << c.optimum << ',' << c.gap_4 << ',' << c.gap_8 << ',' << c.gap_24 << ','
      << c.max_norm_deviation_4 << ',' << c.mean_norm_deviation_4 << '\n';
  };
  const char* header = "keys         optimum   gap 4 frames  8 frames  24 frames   max ||q|-1|  mean ||q|-1|  mean/max\n";
  std::printf("the example (docs/examples/quaternion-splines-7keys.txt):\n%s", header);
  row("example", "example", key_set_claims(seven_keyframe_example()));
  // Steps like the example's, and steps of a third of that.
  const struct {
    const char* family;
    double min_step, max_step;
  } families[] = {{"steps 30-50", 30.0, 50.0}, {"steps 10-20", 10.0, 20.0}};
  for (const auto& fam : families) {
    std::printf("\nrandom key sets, %s degrees on S3 between keys:\n%s", fam.family, header);
    std::vector<double> gap4, gap8, ratio, max_dev;
    int within = 0;
    for (int s = 1; s <= seeds; ++s) {
      const KeySetClaims c =
          key_set_claims(random_seven_keyframes(static_cast<std::uint64_t>(s), fam.min_step, fam.max_step));
      row(fam.family, "seed " + std::to_string(s), c);
      gap4.push_back(c.gap_4);
      gap8.push_back(c.gap_8);
      ratio.push_back(c.mean_norm_deviation_4 / c.max_norm_deviation_4);
      max_dev.push_back(c.max_norm_deviation_4);
      within += c.gap_4 <= 1e-3;
    }
    if (seeds > 0) {
      std::printf("%d key sets (min / median / max): gap with 4 frames %s %% (within 0.1 %% in %d), with 8 frames %s %%;\n"
                  "  max ||q|-1| %s %%; mean/max %s\n",
                  seeds, spread(gap4, 100).c_str(), within, spread(gap8, 100).c_str(), spread(max_dev, 100).c_str(),
                  spread(ratio, 1).c_str());
    }
  }
  return finish_csv(f, out);
}

// Rodrigues et al.'s Figure 6: the segment for k = 1, 2, 3 with the corrected v_{i+1}, the
// construction curves of step 1 (k = 2), and the printed v_{i+1} after projection.
int reproduce_rodrigues_figure6(const std::filesystem::path& out) {
  using namespace geometric_splines;
  std::ofstream f = open_csv(out, "curve,u,x,y,z");
  if (!f) {
    std::cerr << "posefair reproduce: cannot write " << out << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  const Figure6Data d = figure6_data();
  std::printf("Figure 6 data: p_i.v_i = %.3g; printed v_i+1: p_i+1.v_i+1 = %.3g; corrected (-1/10, ...): %.3g\n",
              d.p0.dot(d.v0), d.p1.dot(d.v1_printed), d.p1.dot(d.v1_corrected));
  constexpr int kSamples = 200;
  auto write = [&](const std::string& name, auto&& point) {
    double worst = 0.0, length = 0.0;
    SpherePoint<3> last = point(0.0);
    for (int i = 0; i <= kSamples; ++i) {
      const double u = static_cast<double>(i) / kSamples;
      const SpherePoint<3> x = point(u);
      worst = std::max(worst, std::abs(x.norm() - 1.0));
      length += (x - last).norm();
      last = x;
      char line[160];
      std::snprintf(line, sizeof line, "%s,%.4f,%.15g,%.15g,%.15g\n", name.c_str(), u, x.x(), x.y(), x.z());
      f << line;
    }
    std::printf("  %-18s length %.4f, max | |s| - 1 | %.2g\n", name.c_str(), length, worst);
  };
  for (int k = 1; k <= 3; ++k) {
    const SmoothingFunction phi(k);
    write("s-k" + std::to_string(k), [&](double u) { return sphere_segment<3>(phi, d.p0, d.v0, d.p1, d.v1_corrected, 1.0, u); });
  }
  const SmoothingFunction phi2(2);
  const SpherePoint<3> v1_projected = project_to_tangent<3>(d.p1, d.v1_printed);
  write("s-k2-printed-v", [&](double u) { return sphere_segment<3>(phi2, d.p0, d.v0, d.p1, v1_projected, 1.0, u); });
  write("l", [&](double u) { return sphere_geodesic<3>(d.p0, d.v0, u); });
  write("c", [&](double u) { return sphere_arc<3>(d.p0, d.p1, u); });
  write("r", [&](double u) { return sphere_geodesic<3>(d.p1, d.v1_corrected, u - 1.0); });
  return finish_csv(f, out);
}

}  // namespace

void add_reproduce_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("reproduce", "Reproduce a source paper's experiments as CSV (see docs/)");
  cmd->require_subcommand(1);
  auto* ls = cmd->add_subcommand("lee-shin",
                                 "Lee & Shin Section 6: error and acceleration vs iteration; beside the CSV, "
                                 "Fig. 1's loop at the bound (-bound.csv), claim (a) by curvature (-curvature.csv) "
                                 "and the motions of Figs. 6-8 (-motion.csv)");
  auto out = std::make_shared<std::string>("lee-shin-section6.csv");
  auto iterations = std::make_shared<int>(1000);
  auto seeds = std::make_shared<int>(5);
  ls->add_option("-o,--output", *out, "CSV file to write")->capture_default_str();
  ls->add_option("--iterations", *iterations, "sweeps per run")->capture_default_str()->check(CLI::Range(1, 100000));
  ls->add_option("--seeds", *seeds, "random sequences averaged per run")->capture_default_str()->check(CLI::Range(1, 1000));
  ls->callback([=, &exit_code] { exit_code = reproduce_lee_shin(*out, *iterations, *seeds); });

  auto* rb = cmd->add_subcommand("ramamoorthi-barr",
                                 "Ramamoorthi & Barr Section 4: 4 variable frames against the optimum and the norm "
                                 "deviation, on the example and on seeded random key sets");
  auto rb_out = std::make_shared<std::string>("ramamoorthi-barr.csv");
  auto key_sets = std::make_shared<int>(10);
  rb->add_option("-o,--output", *rb_out, "CSV file to write")->capture_default_str();
  rb->add_option("--seeds", *key_sets, "random key sets (seeds 1 .. N) besides the example")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  rb->callback([=, &exit_code] { exit_code = reproduce_ramamoorthi_barr(*rb_out, *key_sets); });

  auto* fig6 = cmd->add_subcommand("rodrigues-figure6",
                                   "Rodrigues, Silva Leite & Jakubiak Figure 6: the spline segment on S2 "
                                   "(corrected v_i+1, ERRATA 3) for k = 1, 2, 3");
  auto fig6_out = std::make_shared<std::string>("rodrigues-figure6.csv");
  fig6->add_option("-o,--output", *fig6_out, "CSV file to write")->capture_default_str();
  fig6->callback([=, &exit_code] { exit_code = reproduce_rodrigues_figure6(*fig6_out); });
}

}  // namespace posefair::tools
