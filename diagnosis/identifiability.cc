#include "diagnosis/identifiability.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <set>

#include "odometry/parallel_for.h"

namespace fitcal {

namespace {

constexpr int kN = omni3::kNumParameters;
using Matrix9 = Eigen::Matrix<double, kN, kN>;

const char* const kGroupSymbol[] = {"R", "r", "delta"};
const char* const kWheel[] = {"a", "b", "c"};
const char* const kGroupWords[] = {"distance from the centre to each wheel", "radius of each wheel",
                                   "angular position of each wheel"};

// Relative units (header): s_k = p_k for the lengths, 1 rad for the angles.
Omni3Vector RelativeScale(const Omni3ParameterArray& p) {
  Omni3Vector s;
  for (int k = 0; k < kN; ++k) s[k] = k < omni3::kAngleIndex ? std::abs(p[k]) : 1.0;
  return s;
}

struct Diagnosis {
  Omni3Vector singular_values = Omni3Vector::Zero();  // of J_rel, descending
  Matrix9 v = Matrix9::Identity();                    // right singular vectors (columns)
  double condition_number = 0.0;
  bool rank_deficient = false;
  bool ill_conditioned = false;
  Matrix9 correlation = Matrix9::Identity();
  std::vector<CorrelatedPair> pairs;
  bool Flagged() const { return rank_deficient || ill_conditioned || !pairs.empty(); }
};

Diagnosis Diagnose(const Eigen::MatrixXd& jacobian, const Omni3Vector& scale,
                   const IdentifiabilityOptions& options) {
  Diagnosis d;
  const Eigen::MatrixXd j_rel = jacobian * scale.asDiagonal();
  // Pad to at least nine rows so the thin SVD always yields nine singular values.
  Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(std::max<Eigen::Index>(j_rel.rows(), kN), kN);
  padded.topRows(j_rel.rows()) = j_rel;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(padded, Eigen::ComputeThinV);
  d.singular_values = svd.singularValues();
  d.v = svd.matrixV();
  const double s_max = d.singular_values[0];
  const double s_min = d.singular_values[kN - 1];
  d.rank_deficient = !(s_max > 0.0) || s_min <= options.rank_tolerance * s_max;
  d.condition_number = d.rank_deficient ? std::numeric_limits<double>::infinity() : s_max / s_min;
  d.ill_conditioned = d.condition_number > options.max_condition_number;
  // Covariance shape (J_rel^T J_rel)^+ from the SVD; its correlation does not depend on units.
  Omni3Vector inv_s2 = Omni3Vector::Zero();
  for (int i = 0; i < kN; ++i) {
    const double s = d.singular_values[i];
    if (s > options.rank_tolerance * s_max && s > 0.0) inv_s2[i] = 1.0 / (s * s);
  }
  const Matrix9 cov = d.v * inv_s2.asDiagonal() * d.v.transpose();
  for (int a = 0; a < kN; ++a) {
    for (int b = 0; b < kN; ++b) {
      const double den = std::sqrt(cov(a, a) * cov(b, b));
      d.correlation(a, b) = den > 0.0 ? cov(a, b) / den : (a == b ? 1.0 : 0.0);
    }
  }
  for (int a = 0; a < kN; ++a) {
    for (int b = a + 1; b < kN; ++b) {
      if (std::abs(d.correlation(a, b)) > options.max_abs_correlation) {
        d.pairs.push_back({a, b, d.correlation(a, b)});
      }
    }
  }
  return d;
}

std::string Signed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.2f", v);
  return buf;
}

// Words for one direction in relative units (see header).
std::string DescribeDirection(Omni3Vector u) {
  int k_max = 0;
  for (int k = 1; k < kN; ++k) {
    if (std::abs(u[k]) > std::abs(u[k_max])) k_max = k;
  }
  if (u[k_max] < 0.0) u = -u;
  const double big = std::abs(u[k_max]);
  std::set<int> groups;
  std::vector<int> significant;
  for (int k = 0; k < kN; ++k) {
    if (std::abs(u[k]) >= 0.2 * big) {
      significant.push_back(k);
      groups.insert(k / omni3::kNumWheels);
    }
  }
  // "Common" pattern: every member of the involved groups moves with one sign and similar size.
  bool common = true;
  double lo = big, hi = 0.0;
  for (int g : groups) {
    for (int i = 0; i < omni3::kNumWheels; ++i) {
      const double v = u[g * omni3::kNumWheels + i];
      if (v <= 0.0) common = false;
      lo = std::min(lo, std::abs(v));
      hi = std::max(hi, std::abs(v));
    }
  }
  common = common && hi < 1.5 * lo;
  std::string words;
  if (common) {
    if (groups == std::set<int>{0, 1}) {
      words = "a common scale of all r_i and R_i";
    } else if (groups == std::set<int>{0}) {
      words = "a common scale of all R_i (how fast equal wheel speeds turn the robot)";
    } else if (groups == std::set<int>{1}) {
      words = "a common scale of all r_i (the size of every motion)";
    } else if (groups == std::set<int>{2}) {
      words = "a common rotation of all delta_i (the whole wheel layout turned)";
    }
  }
  // "Difference" pattern: one group, mixed signs summing to about zero.
  if (words.empty() && groups.size() == 1) {
    const int g = *groups.begin();
    const double sum = u[3 * g] + u[3 * g + 1] + u[3 * g + 2];
    if (std::abs(sum) < 0.2 * u.segment<3>(3 * g).norm()) {
      const char* what[] = {"differences between the R_i (how spinning in place shifts the robot)",
                            "differences between the r_i", "differences between the delta_i"};
      words = what[g];
    }
  }
  std::string combination;
  for (int k : significant) {
    if (!combination.empty()) combination += " ";
    combination += Signed(u[k]) + " " + ParameterName(k);
  }
  if (words.empty()) words = "a combined change";
  return words + " [direction in relative units (dR/R, dr/r, d delta in rad): " + combination + "]";
}

std::string JoinLabels(const std::vector<std::string>& labels) {
  std::string out;
  for (const std::string& l : labels) out += (out.empty() ? "" : ", ") + l;
  return out;
}

}  // namespace

std::string ParameterName(int k) {
  return std::string(kGroupSymbol[k / omni3::kNumWheels]) + "_" + kWheel[k % omni3::kNumWheels];
}

bool IdentifiabilityOptions::IsValid(std::string* error) const {
  if (!(rank_tolerance > 0.0 && rank_tolerance < 1.0)) {
    *error = "rank_tolerance must be in (0, 1)";
    return false;
  }
  if (!(max_condition_number > 1.0)) {
    *error = "max_condition_number must exceed 1";
    return false;
  }
  if (!(max_abs_correlation > 0.0 && max_abs_correlation < 1.0)) {
    *error = "max_abs_correlation must be in (0, 1)";
    return false;
  }
  return true;
}

Eigen::MatrixXd FinalPoseJacobian(const Omni3ParameterArray& p, const std::vector<AlignedRun>& runs,
                                  const ResidualWeights& weights, int num_threads) {
  Eigen::MatrixXd j(3 * static_cast<Eigen::Index>(runs.size()), kN);
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    std::unique_ptr<ceres::CostFunction> cost(Omni3FinalPoseResidual::Create(runs[i], weights));
    double residual[3];
    Eigen::Matrix<double, 3, kN, Eigen::RowMajor> block;
    double* jacobians[1] = {block.data()};
    const double* parameters[1] = {p.data()};
    if (!cost->Evaluate(parameters, residual, jacobians)) {
      throw std::runtime_error("run " + runs[i].id + ": the final-pose Jacobian is not finite");
    }
    j.middleRows<3>(3 * static_cast<Eigen::Index>(i)) = block;
  });
  return j;
}

AlignedRun CandidateRun(const CandidateMotion& motion, const Omni3ParameterArray& commanded,
                        double period_s) {
  AlignedRun run;
  run.id = motion.label;
  run.trajectory = motion.label;
  const Eigen::Vector3d w = omni3::KinematicMatrix(commanded.data()) *
                            Eigen::Vector3d(motion.vx_m_s, motion.vy_m_s, motion.omega_rad_s);
  const int n = std::max(1, static_cast<int>(std::ceil(motion.duration_s / period_s)));
  run.samples.resize(static_cast<std::size_t>(n));
  for (auto&& s : run.samples) {
    s.dt_s = motion.duration_s / n;
    for (int i = 0; i < 3; ++i) s.value[i] = w[i];
  }
  run.t_final_s = motion.duration_s;
  return run;
}

IdentifiabilityReport AnalyseIdentifiability(const Eigen::MatrixXd& jacobian,
                                             const Omni3ParameterArray& p,
                                             const std::vector<CandidateMotion>& candidates,
                                             const Omni3ParameterArray& commanded,
                                             const ResidualWeights& weights,
                                             const IdentifiabilityOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("IdentifiabilityOptions: " + error);
  const Omni3Vector scale = RelativeScale(p);
  const Diagnosis d = Diagnose(jacobian, scale, options);
  IdentifiabilityReport report;
  report.rank_deficient = d.rank_deficient;
  report.ill_conditioned = d.ill_conditioned;
  report.condition_number = d.condition_number;
  report.correlation = d.correlation;
  report.correlated_pairs = d.pairs;
  const double s_max = d.singular_values[0];
  report.singular_values_rel =
      s_max > 0.0 ? Omni3Vector(d.singular_values / s_max) : d.singular_values;
  report.identifiable = !d.Flagged();
  if (report.identifiable) return report;

  // Weak subspace: every direction beyond the condition limit; at least the weakest one.
  std::vector<int> weak;
  for (int i = 0; i < kN; ++i) {
    if (report.singular_values_rel[i] * options.max_condition_number < 1.0) weak.push_back(i);
  }
  if (weak.empty()) weak.push_back(kN - 1);
  Eigen::MatrixXd basis(kN, static_cast<Eigen::Index>(weak.size()));
  for (std::size_t c = 0; c < weak.size(); ++c) {
    basis.col(static_cast<Eigen::Index>(c)) = d.v.col(weak[c]);
    WeakDirection w;
    w.direction_rel = d.v.col(weak[c]);
    w.relative_singular_value = report.singular_values_rel[weak[c]];
    w.description = DescribeDirection(w.direction_rel);
    report.weak_directions.push_back(w);
  }
  for (int k = 0; k < kN; ++k) {
    // Length of the projection of parameter k's axis onto the weak subspace.
    if ((basis.transpose() * Omni3Vector::Unit(k)).norm() > 0.9) {
      report.unobservable_parameters.push_back(ParameterName(k));
    }
  }

  // Advice: which kinds of candidate trajectories, one repetition added, remove every symptom.
  if (!candidates.empty()) {
    std::vector<AlignedRun> runs;
    for (const CandidateMotion& c : candidates) runs.push_back(CandidateRun(c, commanded));
    const Eigen::MatrixXd j_cand = FinalPoseJacobian(p, runs, weights, 1);
    std::vector<std::string> kinds;
    for (const CandidateMotion& c : candidates) {
      if (std::find(kinds.begin(), kinds.end(), c.kind) == kinds.end()) kinds.push_back(c.kind);
    }
    auto fixes = [&](const std::set<std::string>& chosen) {
      std::vector<Eigen::Index> rows;
      for (std::size_t i = 0; i < candidates.size(); ++i) {
        if (chosen.count(candidates[i].kind)) rows.push_back(static_cast<Eigen::Index>(i));
      }
      Eigen::MatrixXd stacked(jacobian.rows() + 3 * static_cast<Eigen::Index>(rows.size()), kN);
      stacked.topRows(jacobian.rows()) = jacobian;
      for (std::size_t r = 0; r < rows.size(); ++r) {
        stacked.middleRows<3>(jacobian.rows() + 3 * static_cast<Eigen::Index>(r)) =
            j_cand.middleRows<3>(3 * rows[r]);
      }
      return !Diagnose(stacked, scale, options).Flagged();
    };
    // Single kinds first; if none suffices, pairs; then all.
    for (std::size_t size = 1; size <= kinds.size() && report.fixing_kinds.empty(); ++size) {
      for (std::size_t mask = 1; mask < (std::size_t{1} << kinds.size()); ++mask) {
        std::set<std::string> chosen;
        for (std::size_t i = 0; i < kinds.size(); ++i) {
          if (mask & (std::size_t{1} << i)) chosen.insert(kinds[i]);
        }
        if (chosen.size() != size || !fixes(chosen)) continue;
        std::string name, labels;
        std::vector<std::string> members;
        for (const std::string& k : chosen) name += (name.empty() ? "" : " + ") + k;
        for (const CandidateMotion& c : candidates) {
          if (chosen.count(c.kind)) members.push_back(c.label);
        }
        report.fixing_kinds.push_back(name);
        report.fixing_labels.push_back(JoinLabels(members));
      }
    }
  }
  return report;
}

std::vector<std::string> IdentifiabilityLines(const IdentifiabilityReport& r) {
  std::vector<std::string> lines;
  if (r.identifiable) return lines;
  char buf[256];
  std::string why;
  if (r.rank_deficient) why = "rank deficient";
  if (r.ill_conditioned && !r.rank_deficient) {
    std::snprintf(buf, sizeof buf, "ill-conditioned, condition number %.3g", r.condition_number);
    why = buf;
  }
  if (!r.correlated_pairs.empty())
    why += std::string(why.empty() ? "" : ", ") + "strongly correlated parameters";
  lines.push_back("warning: the training runs cannot determine all nine parameters (" + why + ")");
  for (const CorrelatedPair& p : r.correlated_pairs) {
    std::snprintf(buf, sizeof buf, "  correlation(%s, %s) = %+.4f", ParameterName(p.a).c_str(),
                  ParameterName(p.b).c_str(), p.correlation);
    lines.push_back(buf);
  }
  if (!r.unobservable_parameters.empty()) {
    std::set<int> groups;
    std::string names;
    for (const std::string& n : r.unobservable_parameters) {
      names += (names.empty() ? "" : ", ") + n;
    }
    for (int k = 0; k < kN; ++k) {
      if (std::find(r.unobservable_parameters.begin(), r.unobservable_parameters.end(),
                    ParameterName(k)) != r.unobservable_parameters.end()) {
        groups.insert(k / omni3::kNumWheels);
      }
    }
    std::string what;
    for (int g : groups) what += (what.empty() ? "" : "; ") + std::string(kGroupWords[g]);
    lines.push_back("  not determined at all: " + names + " (" + what + ")");
  }
  for (const WeakDirection& w : r.weak_directions) {
    std::snprintf(buf, sizeof buf,
                  "  unseen direction (%.2g of the best-seen): ", w.relative_singular_value);
    lines.push_back(buf + w.description);
  }
  if (!r.fixing_kinds.empty()) {
    for (std::size_t i = 0; i < r.fixing_kinds.size(); ++i) {
      lines.push_back("  would be fixed by adding " + r.fixing_kinds[i] + " runs (" +
                      r.fixing_labels[i] + ")");
    }
  }
  return lines;
}

}  // namespace fitcal
