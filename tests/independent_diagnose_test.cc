// `fitcal diagnose` held to physics it was not written with. The independent simulator
// (tests/independent_sim/everyday_drive_sim.h: continuous-time differential drive, gear play,
// traction, wandering slip; no fitcal code) drives a robot with one physical mechanism at a time;
// the data set is written as a user records it and `fitcal diagnose` runs on it through the
// command line, as a user runs it. Over five seeds per mechanism:
// - every mechanism that an effect of fitcal's library describes is named as that effect
//   (verdict EFFECTS_NAMED, the effect among the accepted ones) in at least four seeds, and in
//   none is another effect named or nothing said (the report leaves the structure unexplained or
//   says in words that the runs cannot tell the effect from the parameters);
// - a mechanism outside the library is reported as unexplained structure (UNEXPLAINED, or
//   PARTIAL: effects listed as a partial description, never named as the cause);
// - a clean robot (geometry and encoder scale off the nominal, wandering slip) is silent
//   (NOTHING_FOUND).
// Data per seed: 8 random trajectories of 5 manoeuvres (straights and arcs forward and in reverse
// at 0.15 and 0.35 m/s, turns in place both ways, a stop after each; 3-6 m, 25-40 s) x 4
// repetitions; repetitions 1-2 train, 3-4 validate (diagnose's --train-reps auto); each
// repetition drives its manoeuvres within +-3 % of the plan's speeds and durations. Encoders 4096
// ticks at 50 Hz, motion capture 1 mm / 0.1 deg at 25 Hz.
// The mechanisms' sizes are a few times what the runs resolve (each one's comment), so a miss is
// the library's or the tracing's, not the data's.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "tests/independent_sim/everyday_drive_sim.h"
#include "tests/test_files.h"

namespace independent_diagnose_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;
namespace sim = independent_sim;

constexpr int kSeeds = 5;
constexpr int kTrajectories = 8;
constexpr int kRepetitions = 4;

// What diagnose must say of a robot.
// kNotMisattributed: the effect named, or the structure reported unexplained (a mechanism the
// library describes only in part).
enum class Expect { kNamed, kNotMisattributed, kUnexplained, kSilent };

struct Case {
  std::string name;
  Expect expect;
  std::string effect;  // the library effect to name (kNamed)
  sim::Mechanisms mechanisms;
  double backlash_rad = 0.0;
};

// The robot every case starts from: radii and separation off the nominal (0.042, 0.042, 0.2), an
// encoder counting 0.4 % fast, the simulator's wandering slip; no traction creep (that is an
// acceleration slip, a mechanism of its own below).
sim::ContactPhysics CleanPhysics() {
  sim::ContactPhysics physics;
  physics.traction_slip_per_m_s2 = 0.0;
  return physics;
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
  const auto add = [&](const std::string& name, Expect expect, const std::string& effect,
                       const auto& set) {
    Case c{name, expect, effect, {}, 0.0};
    set(&c);
    cases.push_back(c);
  };
  add("clean", Expect::kSilent, "", [](Case*) {});
  // Library effects, one physical cause each.
  add("mocap_latency", Expect::kNamed, "time_offset",
      [](Case* c) { c->mechanisms.mocap_latency_s = 0.04; });
  add("speed_slip", Expect::kNamed, "wheel_speed_slip",
      [](Case* c) { c->mechanisms.speed_slip_s_per_m = 0.08; });  // 2.8 % at 0.35 m/s
  add("tread_asymmetry", Expect::kNamed, "direction_radius",
      [](Case* c) { c->mechanisms.tread_asymmetry = 0.01; });
  // 35 % slip at the peak of a hard start (4.4 m/s^2): a slippery floor; the body lags the
  // wheels by about 5 mm at 0.35 m/s.
  add("traction_creep", Expect::kNamed, "acceleration_slip",
      [](Case* c) { c->mechanisms.traction_creep_s2_per_m = 0.08; });
  // Wheels that slide beyond mu g = 1.5 m/s^2: a saturation, which the library's linear creep
  // describes only in part. Named as acceleration_slip, or structure left unexplained; never
  // another effect.
  add("traction_limit", Expect::kNotMisattributed, "acceleration_slip",
      [](Case* c) { c->mechanisms.traction_limit_m_s2 = 1.5; });
  add("gear_play", Expect::kNamed, "backlash", [](Case* c) { c->backlash_rad = 0.12; });
  add("slope", Expect::kNamed, "floor_slope", [](Case* c) {
    c->mechanisms.slope_creep_m_s = 0.004;
    c->mechanisms.slope_direction_rad = 0.7;
  });
  add("turn_scrub", Expect::kNamed, "yaw_rate_slip",
      [](Case* c) { c->mechanisms.scrub_slip_s_per_rad = 0.05; });
  add("eccentric_hub", Expect::kNamed, "once_per_revolution", [](Case* c) {
    c->mechanisms.hub_eccentricity = 0.03;  // the registry's realistic 3 %
    c->mechanisms.hub_phase_rad = 0.6;
  });
  add("contact_shift", Expect::kNamed, "pivot_yaw_gain",
      [](Case* c) { c->mechanisms.contact_shift_m = 0.0015; });
  add("marker_offset", Expect::kNamed, "ground_truth_offset", [](Case* c) {
    c->mechanisms.marker_x_m = 0.03;
    c->mechanisms.marker_y_m = -0.02;
  });
  // Outside the library.
  add("carpet_grain", Expect::kUnexplained, "", [](Case* c) {
    c->mechanisms.carpet_grain = 0.02;
    c->mechanisms.grain_direction_rad = 0.5;
  });
  add("side_slip", Expect::kUnexplained, "", [](Case* c) { c->mechanisms.side_slip_s = 0.03; });
  return cases;
}

// What diagnose said: the page's verdict level and the effects it accepted.
struct Said {
  std::string level;
  std::set<std::string> accepted;
  std::string text;
};

Said DiagnoseSeed(const Case& c, int seed) {
  TempDir dir;
  const sim::DiffDriveGeometry truth, nominal{0.042, 0.042, 0.2};
  sim::ContactPhysics physics = CleanPhysics();
  physics.backlash_rad = c.backlash_rad;
  sim::Sensors sensors;
  sensors.encoder_scale = 1.004;
  sensors.mocap_period_s = 0.04;
  std::vector<sim::LabelledRun> runs;
  for (int k = 0; k < kTrajectories; ++k) {
    std::mt19937_64 plan_rng(1000u * static_cast<unsigned>(seed) + static_cast<unsigned>(k));
    sim::Manoeuvres plan;
    plan.manoeuvres = 5;
    const std::vector<sim::Command> commands = sim::ManoeuvreCommands(plan, plan_rng);
    for (int rep = 1; rep <= kRepetitions; ++rep) {
      std::mt19937_64 noise(7919u * static_cast<unsigned>(seed) + 101u * k + rep);
      runs.push_back({"m" + std::to_string(k + 1), rep,
                      sim::SimulateCommands(truth, physics, c.mechanisms, sensors,
                                            sim::RepeatCommands(commands, 0.03, noise), noise)});
    }
  }
  sim::WriteLabelledDataSet(dir.path() / "data", runs, nominal, sensors);
  // One thread: ctest already runs two tests at once on the two cores, and diagnose's threads
  // cost ~14 % more CPU in synchronisation (gear_play seed 3: 2.8 s against 3.25 s user + sys);
  // the output is the same.
  const auto r = RunFitcal(dir, "diagnose --threads 1 --logs " + dir.Path("data") + " --out " +
                                    dir.Path("out"));
  Said said;
  said.text = r.out + r.err;
  if (r.exit_code != 0) {
    said.level = "exit " + std::to_string(r.exit_code);
    return said;
  }
  const YAML::Node metrics = YAML::LoadFile(dir.Path("out/metrics.json"));
  said.level = metrics["verdict"]["level"].as<std::string>();
  for (const YAML::Node& candidate : metrics["candidates"]) {
    if (candidate["accepted"].as<bool>()) said.accepted.insert(candidate["effect"].as<std::string>());
  }
  return said;
}

bool Named(const Case& c, const Said& said) {
  return said.level == "EFFECTS_NAMED" && said.accepted.count(c.effect) == 1;
}

// No effect named, and the report says in words that the runs cannot tell the effect from the
// model's parameters (its predicted sigma too large for its size): diagnose's honest answer when
// the data do not separate it, never a wrong name.
bool SaidInseparable(const Case& c, const Said& said) {
  return said.level != "EFFECTS_NAMED" &&
         said.text.find(c.effect + " cannot be told apart from the model on these runs") !=
             std::string::npos;
}

bool Passes(const Case& c, const Said& said) {
  switch (c.expect) {
    case Expect::kNamed:
    case Expect::kNotMisattributed:
      // Never a wrong name, never silence: the effect named, structure left unexplained (or
      // effects listed as a partial description only), or the effect said to be inseparable.
      return Named(c, said) || said.level == "UNEXPLAINED" || said.level == "PARTIAL" ||
             SaidInseparable(c, said);
    case Expect::kUnexplained:
      return said.level == "UNEXPLAINED" || said.level == "PARTIAL";
    case Expect::kSilent:
      return said.level == "NOTHING_FOUND";
  }
  return false;
}

class IndependentDiagnose : public ::testing::TestWithParam<Case> {};

TEST_P(IndependentDiagnose, SaysWhatThePhysicsIs) {
  const Case& c = GetParam();
  int passed = 0, named = 0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const Said said = DiagnoseSeed(c, seed);
    std::string accepted;
    for (const std::string& e : said.accepted) accepted += (accepted.empty() ? "" : ",") + e;
    const bool ok = Passes(c, said);
    passed += ok ? 1 : 0;
    named += c.expect == Expect::kNamed && Named(c, said) ? 1 : 0;
    std::printf("%-16s seed %d: %-14s accepted {%s}%s\n", c.name.c_str(), seed,
                said.level.c_str(), accepted.c_str(), ok ? "" : "  <- wrong");
    if (!ok) std::printf("%s\n", said.text.c_str());
  }
  std::printf("%-16s %d of %d seeds as expected%s\n", c.name.c_str(), passed, kSeeds,
              c.expect == Expect::kNamed ? (", named in " + std::to_string(named)).c_str() : "");
  EXPECT_EQ(passed, kSeeds) << c.name;
  // An effect of the library is named in every seed. (Until the held-out test compared windows,
  // the eccentric hub and the traction creep were named in 4 of 5: on seed 2, whose trajectories
  // hold two long fast arcs, the wandering slip accumulated over a run outweighed both effects in
  // the track error from the start - p = 0.0026 and 0.034 against 0.001 and 0.0013;
  // docs/diagnose.md.)
  if (c.expect == Expect::kNamed) {
    EXPECT_EQ(named, kSeeds) << c.name;
  }
}

INSTANTIATE_TEST_SUITE_P(Mechanisms, IndependentDiagnose, ::testing::ValuesIn(Cases()),
                         [](const auto& param) { return param.param.name; });

}  // namespace
