#include "diagnosis/covariate_structure.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>

#include "odometry/text_format.h"

namespace fitcal {

namespace {

// Below this mean speed a run's direction of travel is its start heading (a turn on the spot).
constexpr double kTravellingSpeedMS = 0.02;
// Permutations of the covariate test (p resolves 1 / (kPermutations + 1) = 5e-4, below Holm's
// smallest threshold for six covariates at 0.01, 1.7e-3); a fixed seed: the same data give the
// same p.
constexpr int kPermutations = 1999;
constexpr std::uint64_t kPermutationSeed = 16;

struct Groups {
  std::vector<std::vector<std::size_t>> members;
  bool within = false;  // trajectories with repetitions (else: all runs, one group)
};

Groups MakeGroups(const ResidualAnalysis& a) {
  std::map<std::string, std::vector<std::size_t>> by_trajectory;
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    by_trajectory[a.runs[i].repetition_group].push_back(i);
  }
  Groups g;
  for (auto& [label, members] : by_trajectory) {
    if (members.size() >= 2) g.members.push_back(members);
  }
  g.within = !g.members.empty();
  if (!g.within) {
    g.members.emplace_back(a.runs.size());
    std::iota(g.members.back().begin(), g.members.back().end(), std::size_t{0});
  }
  return g;
}

struct Covariate {
  std::string name;
  bool direction = false;
  std::vector<std::vector<double>> value;  // [run][column]
  // The smallest within-group RMS spread that is a real difference (the covariate's resolution):
  // a direction of travel that differs by rounding only (every run starts at the same heading)
  // is not a covariate, however its relative spread reads.
  double resolution = 0.0;
  // Instead of value: the alternative's own regressor per run, 3 x m (the absolute wheel angle,
  // whose exposure is an integral over the run, not one number); `why_not` when unavailable.
  std::vector<Eigen::MatrixXd> regressor;
  std::string why_not;
};

// Run order: the encoder clock's start time when the runs' windows never overlap (the logs share
// a session clock), else the repetition number (repetitions are recorded in order).
std::vector<std::vector<double>> RunOrder(const ResidualAnalysis& a) {
  std::vector<std::size_t> order(a.runs.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    return a.runs[i].t_start_s < a.runs[j].t_start_s;
  });
  bool session_clock = order.size() >= 2;
  for (std::size_t k = 1; k < order.size(); ++k) {
    const RunFeatures& prev = a.runs[order[k - 1]];
    session_clock = session_clock && a.runs[order[k]].t_start_s >= prev.t_start_s + prev.duration_s;
  }
  std::vector<std::vector<double>> out;
  for (const RunFeatures& f : a.runs) {
    out.push_back({session_clock ? f.t_start_s : static_cast<double>(f.repetition)});
  }
  return out;
}

// Resolutions (Covariate::resolution): 1 mrad of direction on the unit circle, 1 mm, 0.1 mm/s,
// half a turning sign; run order: 1 ms of session clock or half a repetition.
constexpr double kDirectionResolution = 1e-3;
constexpr double kDistanceResolutionM = 1e-3;
constexpr double kSpeedResolutionMS = 1e-4;

std::vector<Covariate> MakeCovariates(const ResidualAnalysis& a) {
  std::vector<Covariate> out;
  out.push_back({"run order within the session", false, RunOrder(a), 1e-3, {}, {}});
  Covariate world{"world-frame direction of travel", true, {}, kDirectionResolution, {}, {}};
  Covariate distance{"distance travelled", false, {}, kDistanceResolutionM, {}, {}};
  Covariate speed{"speed", false, {}, kSpeedResolutionMS, {}, {}};
  Covariate turning{"turning direction", false, {}, 0.5, {}, {}};
  for (const RunFeatures& f : a.runs) {
    const double phi = f.start_heading_rad + (f.speed_m_s > kTravellingSpeedMS ? f.alpha_rad : 0.0);
    world.value.push_back({std::cos(phi), std::sin(phi)});
    distance.value.push_back({f.distance_m});
    speed.value.push_back({f.speed_m_s});
    turning.value.push_back({static_cast<double>(f.rotation_sign)});
  }
  for (Covariate* c : {&world, &distance, &speed, &turning}) out.push_back(std::move(*c));
  Covariate wheel{"absolute wheel angle", true, {}, 0.0, a.wheel_angle_jacobian, {}};
  if (wheel.regressor.empty()) {
    wheel.why_not =
        "the logs do not carry the wheels' absolute angles (encoder CSV with cumulative ticks)";
  }
  out.push_back(std::move(wheel));
  return out;
}

// The alternative's regressor of run i, centred in its group: [c~ J_i, c~ I] per column of a
// value covariate (header), or the given regressor minus its group mean.
struct Centred {
  std::vector<Eigen::MatrixXd> x;  // per run, 3 x q_max (zero outside the groups)
  double within = 0.0;             // sum of squares of the centred covariate
  double overall = 0.0;            // ... of the covariate centred over all runs
  double within_rms = 0.0;         // RMS within-group spread, per run and column
};

Centred CentreRegressor(const Groups& g, const Covariate& cov, std::size_t n) {
  Centred out;
  const int m = static_cast<int>(cov.regressor.front().cols());
  out.x.assign(n, Eigen::MatrixXd::Zero(3, m));
  Eigen::MatrixXd mean_all = Eigen::MatrixXd::Zero(3, m);
  for (const auto& x : cov.regressor) mean_all += x / static_cast<double>(n);
  for (const auto& x : cov.regressor) out.overall += (x - mean_all).squaredNorm();
  for (const auto& members : g.members) {
    Eigen::MatrixXd mean = Eigen::MatrixXd::Zero(3, m);
    for (std::size_t i : members) mean += cov.regressor[i] / static_cast<double>(members.size());
    for (std::size_t i : members) {
      out.x[i] = cov.regressor[i] - mean;
      out.within += out.x[i].squaredNorm();
    }
  }
  return out;
}

Centred CentreValues(const Groups& g, const Covariate& cov, int k,
                     const std::vector<Eigen::MatrixXd>& jacobian) {
  Centred out;
  const std::size_t n = cov.value.size();
  const int h = static_cast<int>(cov.value.front().size());
  std::vector<std::vector<double>> centred(n, std::vector<double>(h, 0.0));
  std::size_t count = 0;
  for (int c = 0; c < h; ++c) {
    double mean_all = 0.0;
    for (const auto& v : cov.value) mean_all += v[c] / static_cast<double>(n);
    for (const auto& v : cov.value) out.overall += (v[c] - mean_all) * (v[c] - mean_all);
    for (const auto& members : g.members) {
      double mean = 0.0;
      for (std::size_t i : members) mean += cov.value[i][c] / static_cast<double>(members.size());
      for (std::size_t i : members) {
        centred[i][c] = cov.value[i][c] - mean;
        out.within += centred[i][c] * centred[i][c];
        ++count;
      }
    }
  }
  out.within_rms = std::sqrt(out.within / static_cast<double>(std::max<std::size_t>(1, count)));
  out.x.assign(n, Eigen::MatrixXd::Zero(3, h * (k + 3)));
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < h; ++c) {
      if (k > 0) out.x[i].block(0, c * (k + 3), 3, k) = centred[i][c] * jacobian[i];
      out.x[i].block(0, c * (k + 3) + k, 3, 3) = centred[i][c] * Eigen::Matrix3d::Identity();
    }
  }
  return out;
}

// Whitening of the grouped deviations: rows S^-1/2 (rank r), and the degrees of freedom D.
struct Whitened {
  Eigen::MatrixXd whiten;          // r x 3
  std::vector<Eigen::VectorXd> z;  // per run (empty for runs outside the groups)
  std::vector<bool> in_group;
  double dof = 0.0;    // D
  double total = 0.0;  // SS_tot
};

Whitened Whiten(const ResidualAnalysis& a, const Groups& g) {
  const std::size_t n = a.runs.size();
  std::vector<Eigen::Vector3d> d(n, Eigen::Vector3d::Zero());
  Whitened w;
  w.z.resize(n);
  w.in_group.assign(n, false);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& members : g.members) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t i : members) {
      const Pose2d& e = a.final_start_frame[i];
      mean += Eigen::Vector3d(e.x, e.y, e.theta) / static_cast<double>(members.size());
    }
    for (std::size_t i : members) {
      const Pose2d& e = a.final_start_frame[i];
      d[i] = Eigen::Vector3d(e.x, e.y, e.theta) - mean;
      scatter += d[i] * d[i].transpose();
      w.in_group[i] = true;
    }
    w.dof += static_cast<double>(members.size()) - 1.0;
  }
  if (!(w.dof > 0.0)) return w;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter / w.dof);
  const double largest = eig.eigenvalues().maxCoeff();
  std::vector<Eigen::RowVector3d> rows;
  for (int c = 0; c < 3; ++c) {
    const double lambda = eig.eigenvalues()[c];
    if (lambda > 1e-12 * largest && lambda > 0.0) {
      rows.push_back(eig.eigenvectors().col(c).transpose() / std::sqrt(lambda));
    }
  }
  w.whiten.resize(static_cast<int>(rows.size()), 3);
  for (std::size_t r = 0; r < rows.size(); ++r) w.whiten.row(static_cast<int>(r)) = rows[r];
  for (std::size_t i = 0; i < n; ++i) {
    if (!w.in_group[i]) continue;
    w.z[i] = w.whiten * d[i];
    w.total += w.z[i].squaredNorm();
  }
  return w;
}

// SS_reg of the regression of z_i on the (whitened, centred) alternative of run perm[i]; b and
// proj are workspace (the permutations call this thousands of times).
double Explained(const std::vector<Eigen::MatrixXd>& xw, const Whitened& w,
                 const Eigen::MatrixXd& projector, const std::vector<std::size_t>& perm,
                 Eigen::VectorXd* b, Eigen::VectorXd* proj) {
  b->setZero(projector.rows());
  for (std::size_t i = 0; i < perm.size(); ++i) {
    if (w.in_group[i]) b->noalias() += xw[perm[i]].transpose() * w.z[i];
  }
  proj->noalias() = projector.transpose() * *b;
  return proj->squaredNorm();
}

// p of SS_reg by permuting the alternatives among the runs of each set of repetitions (header):
// exchangeable under "no dependence" whatever each trajectory's own noise level, which the
// F(q, df2) reference assumes equal (measured on clean simulated data with four repetitions:
// 3 of 12 seeds crossed the family-wise 0.01 with the F reference). A is the same for every
// permutation (the same regressors, reassigned), so each costs one b.
double PermutationPValue(const Groups& g, const std::vector<Eigen::MatrixXd>& xw, const Whitened& w,
                         const Eigen::MatrixXd& projector, double observed) {
  std::mt19937_64 rng(kPermutationSeed);
  std::vector<std::size_t> perm(xw.size());
  std::iota(perm.begin(), perm.end(), std::size_t{0});
  int at_least = 0;
  Eigen::VectorXd b, proj;
  for (int n = 0; n < kPermutations; ++n) {
    for (const auto& members : g.members) {
      for (std::size_t j = members.size(); j > 1; --j) {  // Fisher-Yates within the set
        std::swap(perm[members[j - 1]], perm[members[rng() % j]]);
      }
    }
    if (Explained(xw, w, projector, perm, &b, &proj) >= observed * (1.0 - 1e-12)) ++at_least;
  }
  return (1.0 + at_least) / (1.0 + kPermutations);
}

// The F test of one covariate (header). Leaves `test` not tested with the reason when the data
// cannot carry it.
void TestCovariate(const ResidualAnalysis& a, const Groups& g, const Whitened& w,
                   const Covariate& cov, CovariateTest* test) {
  test->name = cov.name;
  test->direction = cov.direction;
  if (!cov.why_not.empty()) {
    test->why_not = cov.why_not;
    return;
  }
  const int r = static_cast<int>(w.whiten.rows());
  if (r == 0) {
    test->why_not = "no scatter to test against";
    return;
  }
  const int k = a.final_jacobian.empty() ? 0 : static_cast<int>(a.final_jacobian.front().cols());
  const Centred centred = cov.regressor.empty() ? CentreValues(g, cov, k, a.final_jacobian)
                                                : CentreRegressor(g, cov, a.runs.size());
  if (!(centred.within > 1e-6 * centred.overall) || !(centred.within > 0.0) ||
      !(centred.within_rms >= cov.resolution)) {
    test->why_not = g.within ? "does not vary between repetitions of a trajectory"
                             : "does not vary between the runs";
    return;
  }
  const int q_max = static_cast<int>(centred.x.front().cols());
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(q_max, q_max);
  std::vector<Eigen::MatrixXd> xw(a.runs.size());
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    if (!w.in_group[i]) continue;
    xw[i] = w.whiten * centred.x[i];
    normal += xw[i].transpose() * xw[i];
  }
  // SS_reg = |P^T b|^2 with P = V diag(lambda^-1/2) over the non-null eigenvectors of A.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normal);
  const double largest = eig.eigenvalues().maxCoeff();
  std::vector<int> kept;
  for (int j = 0; j < q_max; ++j) {
    if (eig.eigenvalues()[j] > 1e-10 * largest) kept.push_back(j);
  }
  const int q = static_cast<int>(kept.size());
  Eigen::MatrixXd projector(q_max, q);
  for (int j = 0; j < q; ++j) {
    projector.col(j) = eig.eigenvectors().col(kept[j]) / std::sqrt(eig.eigenvalues()[kept[j]]);
  }
  // Without repetitions the residuals carry the fit of the k parameters (k / r runs' worth).
  const double dof = w.dof - (g.within ? 0.0 : static_cast<double>(k) / r);
  const double df2 = r * dof - q;
  if (q == 0 || !(df2 >= 1.0)) {
    test->why_not = "too few runs for its alternatives";
    return;
  }
  std::vector<std::size_t> identity(a.runs.size());
  std::iota(identity.begin(), identity.end(), std::size_t{0});
  Eigen::VectorXd b, proj;
  const double explained = std::min(Explained(xw, w, projector, identity, &b, &proj), w.total);
  test->tested = true;
  test->df1 = q;
  test->df2 = df2;
  test->f = (explained / q) / std::max((w.total - explained) / df2, 1e-300);
  test->p_value = PermutationPValue(g, xw, w, projector, explained);
}

}  // namespace

CovariateStructure AnalyzeCovariates(const ResidualAnalysis& analysis, double alpha) {
  CovariateStructure out;
  out.alpha = alpha;
  if (analysis.runs.size() < 3 || analysis.final_jacobian.size() != analysis.runs.size()) {
    return out;
  }
  const Groups groups = MakeGroups(analysis);
  out.within_repetitions = groups.within;
  const Whitened whitened = Whiten(analysis, groups);
  for (const Covariate& c : MakeCovariates(analysis)) {
    CovariateTest test;
    TestCovariate(analysis, groups, whitened, c, &test);
    out.tests.push_back(test);
  }
  // Holm's step-down over the tested covariates.
  std::vector<CovariateTest*> tested;
  for (CovariateTest& t : out.tests) {
    if (t.tested) tested.push_back(&t);
  }
  std::sort(tested.begin(), tested.end(),
            [](const CovariateTest* x, const CovariateTest* y) { return x->p_value < y->p_value; });
  bool rejecting = true;
  for (std::size_t j = 0; j < tested.size(); ++j) {
    tested[j]->holm_threshold = alpha / static_cast<double>(tested.size() - j);
    rejecting = rejecting && tested[j]->p_value < tested[j]->holm_threshold;
    tested[j]->significant = rejecting;
    out.any_significant = out.any_significant || rejecting;
  }
  return out;
}

std::string CovariateFinding(const CovariateTest& t) {
  return StrFormat(
      "unexplained: the residual %s %s (F = %.2f on (%.0f, %.0f) df, p = %.2g, Holm "
      "threshold %.2g)",
      t.direction ? "depends on the" : "drifts with", t.name.c_str(), t.f, t.df1, t.df2, t.p_value,
      t.holm_threshold);
}

std::string FormatCovariateStructure(const CovariateStructure& s) {
  std::string out = StrFormat(
      "Residual against covariates (%s; p from 1999 permutations of the covariate within each "
      "set of repetitions; family-wise alpha %.2g, Holm step-down over the covariates tested):\n\n",
      s.within_repetitions ? "deviations between repetitions of each trajectory"
                           : "all runs, no repetitions",
      s.alpha);
  out += "| covariate | F | df | p | Holm threshold | verdict |\n|---|---|---|---|---|---|\n";
  for (const CovariateTest& t : s.tests) {
    if (!t.tested) {
      out += "| " + t.name + " | - | - | - | - | not tested: " + t.why_not + " |\n";
      continue;
    }
    out += StrFormat("| %s | %.2f | (%.0f, %.0f) | %.2g | %.2g | %s |\n", t.name.c_str(), t.f,
                     t.df1, t.df2, t.p_value, t.holm_threshold, t.significant ? "STRUCTURE" : "-");
  }
  return out;
}

}  // namespace fitcal
