#include "models/model_interface.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

#include "models/model_registry.h"

namespace fitcal {

namespace {

// Up to this many channels every permutation within a kind and every sign pattern is a
// hypothesis (4 wheels: 24 x 16 = 384); beyond it only single swaps and single sign flips, which
// are what a wiring mistake usually is.
constexpr int kMaxChannelsForFullSearch = 4;

std::vector<std::vector<int>> PermutationsWithinKinds(const std::vector<ChannelInfo>& channels) {
  const int n = static_cast<int>(channels.size());
  std::vector<std::vector<int>> out;
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (n <= kMaxChannelsForFullSearch) {
    do {
      bool same_kinds = true;
      for (int i = 0; i < n; ++i)
        same_kinds = same_kinds && channels[order[i]].kind == channels[i].kind;
      if (same_kinds) out.push_back(order);
    } while (std::next_permutation(order.begin(), order.end()));
    return out;
  }
  out.push_back(order);
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (channels[a].kind != channels[b].kind) continue;
      std::vector<int> swapped = order;
      std::swap(swapped[a], swapped[b]);
      out.push_back(swapped);
    }
  }
  return out;
}

std::vector<std::vector<int>> SignPatterns(int n) {
  std::vector<std::vector<int>> out;
  if (n <= kMaxChannelsForFullSearch) {
    for (int bits = 0; bits < (1 << n); ++bits) {
      std::vector<int> sign(n, 1);
      for (int i = 0; i < n; ++i) sign[i] = (bits >> i) & 1 ? -1 : 1;
      out.push_back(sign);
    }
    return out;
  }
  out.emplace_back(n, 1);
  for (int i = 0; i < n; ++i) {
    std::vector<int> sign(n, 1);
    sign[i] = -1;
    out.push_back(sign);
  }
  return out;
}

}  // namespace

std::vector<ChannelMapping> RobotModelInterface::CandidateMiswirings() const {
  const std::vector<ChannelInfo>& channels = robot().channels;
  const int n = static_cast<int>(channels.size());
  std::vector<ChannelMapping> out;
  const auto permutations = PermutationsWithinKinds(channels);
  const auto signs = SignPatterns(n);
  for (const auto& column : permutations) {
    for (const auto& sign : signs) out.push_back({column, sign});
  }
  // The identity first (both generators start with it, so it already is); keep that explicit.
  std::stable_partition(out.begin(), out.end(),
                        [](const ChannelMapping& m) { return m.IsIdentity(); });
  return out;
}

std::optional<int> ParameterIndex(const Robot& robot, const std::string& name) {
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.parameters[k].name == name) return k;
  }
  return std::nullopt;
}

int RequireParameterIndex(const Robot& robot, const std::string& name) {
  const std::optional<int> k = ParameterIndex(robot, name);
  if (!k) {
    throw std::logic_error("robot '" + robot.name + "' (model " + robot.model +
                           ") has no parameter '" + name + "'");
  }
  return *k;
}

std::vector<ClosedFormCalibration> RobotModelInterface::ClosedForms(
    const std::vector<AlignedRun>& training) const {
  std::vector<ClosedFormCalibration> out;
  for (const ClosedForm& form : ExtrasOf(robot().model).closed_forms) {
    if (std::optional<ClosedFormCalibration> c = form.compute(*this, training)) {
      c->method = form.method;
      out.push_back(std::move(*c));
    }
  }
  return out;
}

}  // namespace fitcal
