#include "tools/generalisation_command.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <set>

#include "fit/effect_fit.h"
#include "fit/final_pose_cost.h"
#include "fit/segment_cost.h"
#include "fit/trajectory_split.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/robot_yaml.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "odometry/parallel_for.h"
#include "tools/model_generalise_command.h"

namespace fitcal::tools {

namespace {

struct PreparedRuns {
  std::vector<AlignedRun> aligned;      // never resized after preparation
  std::vector<SegmentedRun> segmented;  // points into `aligned`
  std::vector<std::string> path_type;   // label up to the first '_'
  std::vector<std::string> session;     // the whole label
  std::vector<ClockMap> clock;
  std::vector<TrackRun> tracks;  // clock-mapped ground truth; only for effect models
};

struct Model {
  std::string name;
  bool fit = true;
  FitOptions options;
  bool track = false;  // fit nine + `effects` on the ground-truth tracks (fit/effect_fit.h)
  EffectModel effects;
};

struct Subset {
  std::vector<AlignedRun> final_runs;
  std::vector<SegmentedRun> segmented;
  std::vector<TrackRun> tracks;
};

Subset Select(const PreparedRuns& runs, const std::vector<std::size_t>& idx) {
  Subset s;
  for (std::size_t i : idx) {
    s.final_runs.push_back(runs.aligned[i]);
    s.segmented.push_back(runs.segmented[i]);  // still points into runs.aligned
    if (!runs.tracks.empty()) s.tracks.push_back(runs.tracks[i]);
  }
  return s;
}

struct Row {
  double train_cf = 0.0;
  double test_cf = 0.0;
  double test_position_m = 0.0;
  double test_heading_deg = 0.0;
  double test_segment_cf = 0.0;
  int at_bound = 0;
  bool usable = true;
  bool has_segment_cf = true;
  Omni3ParameterArray p{};
  EffectModel effects;
};

// Nine + effects fitted on the training tracks; test CF from the effect replay's final pose.
Row EvaluateTrackModel(const Model& model, const Omni3Robot& robot, const Subset& train,
                       const Subset& test, int threads) {
  Row row;
  EffectFitOptions o;
  o.num_threads = threads;
  o.compute_covariance = false;
  const EffectFitResult fit =
      FitEffectModel(train.tracks, robot, robot.nominal.ToArray(), model.effects, o);
  std::copy(fit.parameters.begin(), fit.parameters.end(), row.p.begin());
  row.effects = fit.effects;
  row.usable = fit.usable;
  const auto box = robot.ParameterBounds();
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    const double tol = 1e-6 * (box[k].hi - box[k].lo);
    row.at_bound += row.p[k] <= box[k].lo + tol || row.p[k] >= box[k].hi - tol;
  }
  for (const auto& e : row.effects) {
    const auto& info = effects::Info(e.id);
    for (int k = 0; k < info.num_parameters; ++k) {
      const double tol = 1e-6 * (info.upper[k] - info.lower[k]);
      row.at_bound += e.value[k] <= info.lower[k] + tol || e.value[k] >= info.upper[k] - tol;
    }
  }
  row.train_cf = ScoreModel(row.p, row.effects, train.tracks, {}, threads).cf;
  const FinalPoseErrors e =
      FinalPoseErrorsOf(ScoreModel(row.p, row.effects, test.tracks, {}, threads));
  row.test_cf = e.cf;
  row.test_position_m = e.mean_position_error_m;
  row.test_heading_deg = RadToDeg(e.mean_abs_heading_error_rad);
  row.has_segment_cf = false;
  return row;
}

Row Evaluate(const Model& model, const Omni3Robot& robot, const Subset& train, const Subset& test,
             int threads) {
  if (model.track) return EvaluateTrackModel(model, robot, train, test, threads);
  Row row;
  row.p = robot.nominal.ToArray();
  if (model.fit) {
    FitOptions o = model.options;
    o.num_threads = threads;
    const FitResult fit = FitOmni3(train.final_runs, train.segmented, robot, o);
    row.p = fit.parameters;
    row.at_bound = fit.NumAtBound();
    row.usable = fit.usable;
  }
  row.train_cf = EvaluateFinalPoseErrors(row.p, train.final_runs, threads).cf;
  const FinalPoseErrors e = EvaluateFinalPoseErrors(row.p, test.final_runs, threads);
  row.test_cf = e.cf;
  row.test_position_m = e.mean_position_error_m;
  row.test_heading_deg = RadToDeg(e.mean_abs_heading_error_rad);
  row.test_segment_cf = EvaluateSegmentErrors(row.p, test.segmented, threads).cf;
  return row;
}

}  // namespace

void AddGeneraliseOptions(CLI::App& app, GeneraliseCommandOptions& o) {
  AddDatasetOptions(app, o);
  app.add_option("--segment-length-m", o.segment_length_m,
                 "Ground-truth path length of a segment-cost window (m)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("!--no-clock-map", o.clock_map,
               "Do not refine the ground-truth clock before cutting segments");
  app.add_flag("!--no-loso", o.leave_one_session_out, "Skip leave-one-session-out");
  app.add_option("--train-trajectories", o.train_trajectories,
                 "Train on labels matching (list or regular expression), test on the rest, "
                 "and the other way round");
  app.add_option("--effects", o.effects,
                 "Library effects to add as a further model (nine + effects, track cost)")
      ->delimiter(',');
  app.add_option("--train-reps", o.train_reps,
                 "Models other than omni3: repetitions of every path type that train the "
                 "split against the other repetitions (default: the first half present)");
  app.add_option("--sessions", o.sessions,
                 "Models other than omni3: a leave-one-session-out session is a trajectory "
                 "label (label) or a path type + repetition number (repetition)")
      ->capture_default_str();
  app.add_flag("--optiodom", o.optiodom,
               "Models other than omni3: also score OptiOdom's method (Sousa et al. 2022: "
               "position from the start every 0.5 m of path) on the same splits");
}

int RunGeneraliseCommand(const GeneraliseCommandOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    const io::DatasetIndex index = OpenDataset(options).index;
    const std::string model_name = io::ReadRobotModel(index.robot_path);
    if (model_name != "omni3") {
      return RunModelGeneraliseCommand(options, index, ReadRobotModelFile(index.robot_path));
    }
    if (!options.train_reps.empty() || options.sessions != "label" || options.optiodom) {
      std::cerr << "fitcal: generalise --train-reps, --sessions and --optiodom apply to the "
                   "models on the generic path, not to omni3's table (its reduced model is "
                   "OptiOdom's)\n";
      return 2;
    }
    const io::Dataset dataset = LoadRuns(options, index, /*robot=*/nullptr);
    const Omni3Robot robot = io::ReadOmni3Robot(dataset.robot_path);
    SegmentOptions segment_options;
    segment_options.length_m = options.segment_length_m;
    std::string error;
    if (!segment_options.IsValid(&error)) {
      std::cerr << "fitcal: " << error << "\n";
      return 2;
    }

    PreparedRuns runs;
    const std::size_t n = dataset.runs.size();
    runs.aligned = AlignRuns(dataset.runs);
    runs.segmented.resize(n);
    runs.clock.resize(n);
    const auto nominal = robot.nominal.ToArray();
    ParallelFor(n, options.threads, [&](std::size_t i) {
      GroundTruthTrack gt = dataset.runs[i].ground_truth;
      if (options.clock_map) {
        runs.clock[i] = EstimateClockMap(runs.aligned[i], gt, nominal);
        gt = ApplyClockMap(gt, runs.clock[i]);
      }
      runs.segmented[i].run = &runs.aligned[i];
      runs.segmented[i].segments = MakeSegments(runs.aligned[i], gt, segment_options);
    });
    if (!options.effects.empty()) {
      runs.tracks.resize(n);
      ParallelFor(n, options.threads, [&](std::size_t i) {
        RunLog run = dataset.runs[i];
        if (options.clock_map) run.ground_truth = ApplyClockMap(run.ground_truth, runs.clock[i]);
        runs.tracks[i] = PrepareTrackRun(run);
      });
    }
    for (const RunLog& run : dataset.runs) {
      runs.session.push_back(run.trajectory);
      runs.path_type.push_back(run.trajectory.substr(0, run.trajectory.find('_')));
    }
    std::set<std::string> path_types(runs.path_type.begin(), runs.path_type.end());
    std::set<std::string> sessions(runs.session.begin(), runs.session.end());
    if (options.clock_map) {
      double mean_abs_offset = 0.0, mean_abs_rate = 0.0;
      for (const ClockMap& c : runs.clock) {
        mean_abs_offset += std::abs(c.offset_s) / n;
        mean_abs_rate += std::abs(c.rate) / n;
      }
      std::printf(
          "clock map (ground truth onto encoder time, fitted on speed profiles): mean |offset| "
          "%.3f s, mean |rate| %.2f %%\n",
          mean_abs_offset, 100.0 * mean_abs_rate);
    }

    std::vector<Model> models;
    models.push_back({"nominal", false, {}, false, {}});
    Model nine_final{"nine parameters, final-pose cost", true, {}, false, {}};
    models.push_back(nine_final);
    Model nine_segment{"nine parameters, segment cost", true, {}, false, {}};
    nine_segment.options.cost = CostKind::kSegment;
    models.push_back(nine_segment);
    Model reduced_final{"reduced (common R + 3 r), final-pose cost", true, {}, false, {}};
    reduced_final.options.tying = ParameterTying::CommonDistanceThreeRadii();
    models.push_back(reduced_final);
    Model reduced_segment{"reduced (common R + 3 r), segment cost", true, {}, false, {}};
    reduced_segment.options.tying = ParameterTying::CommonDistanceThreeRadii();
    reduced_segment.options.cost = CostKind::kSegment;
    models.push_back(reduced_segment);
    if (!options.effects.empty()) {
      Model nine_track{"nine parameters, track cost", true, {}, false, {}};
      nine_track.track = true;
      models.push_back(nine_track);
      Model with{"nine +", true, {}, false, {}};
      with.track = true;
      for (const std::string& name : options.effects) {
        effects::EffectValue e;
        e.id = effects::EffectIdFromName(name);  // throws with the list of known names
        with.effects.push_back(e);
        with.name += " " + name;
      }
      with.name += ", track cost";
      models.push_back(with);
    }

    std::printf("data set %s: %zu runs, path types:", options.logs.c_str(), n);
    for (const auto& t : path_types) std::printf(" %s", t.c_str());
    std::printf("; segments of %.2f m\n\n", options.segment_length_m);
    std::printf(
        "| trained on -> tested on | model | train CF | test CF | test pos. [m] | test head. [deg] "
        "| test segment CF | params at bound |\n|---|---|---|---|---|---|---|---|\n");
    // The train -> test pairs: every ordered pair of path types, or the selector's matches vs
    // the rest (both ways).
    struct Pair {
      std::string train_name, test_name;
      std::vector<std::size_t> train_idx, test_idx;
    };
    std::vector<Pair> pairs;
    if (!options.train_trajectories.empty()) {
      const TrajectorySelector selector(options.train_trajectories, runs.session);
      Pair a{"'" + options.train_trajectories + "'", "others", {}, {}};
      for (std::size_t i = 0; i < n; ++i)
        (selector.Matches(runs.session[i]) ? a.train_idx : a.test_idx).push_back(i);
      if (a.train_idx.empty() || a.test_idx.empty()) {
        std::cerr << "fitcal: --train-trajectories '" << options.train_trajectories << "' selects "
                  << a.train_idx.size() << " of " << n << " runs; need some on each side\n";
        return 2;
      }
      pairs.push_back(a);
      pairs.push_back({a.test_name, a.train_name, a.test_idx, a.train_idx});
    } else {
      for (const std::string& train_type : path_types) {
        for (const std::string& test_type : path_types) {
          if (train_type == test_type) continue;
          Pair p{train_type, test_type, {}, {}};
          for (std::size_t i = 0; i < n; ++i) {
            if (runs.path_type[i] == train_type) p.train_idx.push_back(i);
            if (runs.path_type[i] == test_type) p.test_idx.push_back(i);
          }
          pairs.push_back(p);
        }
      }
    }
    for (const Pair& pair : pairs) {
      const Subset train = Select(runs, pair.train_idx), test = Select(runs, pair.test_idx);
      for (const Model& model : models) {
        const Row r = Evaluate(model, robot, train, test, options.threads);
        char segment[32] = "-";
        if (r.has_segment_cf) std::snprintf(segment, sizeof segment, "%.4f", r.test_segment_cf);
        std::printf("| %s -> %s | %s | %.4f | %.4f | %.3f | %.2f | %s | %d%s |\n",
                    pair.train_name.c_str(), pair.test_name.c_str(), model.name.c_str(), r.train_cf,
                    r.test_cf, r.test_position_m, r.test_heading_deg, segment, r.at_bound,
                    r.usable ? "" : " (not converged)");
        for (const auto& e : r.effects) {
          const auto& info = effects::Info(e.id);
          std::printf("|  |   %s:", info.name);
          for (int k = 0; k < info.num_parameters; ++k)
            std::printf(" %s = %.4g", info.parameter_names[k], e.value[k]);
          std::printf(" | | | | | | |\n");
        }
      }
    }

    if (options.leave_one_session_out && sessions.size() > 1) {
      std::printf(
          "\nleave-one-session-out (mean over %zu held-out sessions of the session's test CF)\n\n",
          sessions.size());
      std::printf(
          "| model | mean test CF | mean test segment CF | fits with a parameter at a bound |\n"
          "|---|---|---|---|\n");
      for (const Model& model : models) {
        double cf = 0.0, seg = 0.0;
        int bounded = 0;
        for (const std::string& held_out : sessions) {
          std::vector<std::size_t> train_idx, test_idx;
          for (std::size_t i = 0; i < n; ++i)
            (runs.session[i] == held_out ? test_idx : train_idx).push_back(i);
          const Row r = Evaluate(model, robot, Select(runs, train_idx), Select(runs, test_idx),
                                 options.threads);
          cf += r.test_cf / sessions.size();
          seg += r.test_segment_cf / sessions.size();
          bounded += r.at_bound > 0;
        }
        char segment[32] = "-";
        if (!model.track) std::snprintf(segment, sizeof segment, "%.4f", seg);
        std::printf("| %s | %.4f | %s | %d / %zu |\n", model.name.c_str(), cf, segment, bounded,
                    sessions.size());
      }
    }
    return 0;
  });
}

}  // namespace fitcal::tools
