#include "validation/training_runs.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>

#include "odometry/text_format.h"

namespace fitcal {

namespace {

struct Fnv1a64 {
  std::uint64_t hash = 14695981039346656037ull;
  void Add(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      hash ^= bytes[i];
      hash *= 1099511628211ull;
    }
  }
  void Add(const std::string& s) {
    const std::uint64_t n = s.size();
    Add(&n, sizeof n);  // length first: ("ab", "c") and ("a", "bc") differ
    Add(s.data(), s.size());
  }
};

std::vector<int> Repetitions(const std::vector<AlignedRun>& runs) {
  std::set<int> reps;
  for (const AlignedRun& run : runs) reps.insert(run.repetition);
  return {reps.begin(), reps.end()};
}

}  // namespace

std::string TrainingFingerprint(const std::vector<RunLog>& runs,
                                const std::vector<std::string>& training_ids) {
  if (training_ids.empty()) return "";
  std::map<std::string, const RunLog*> by_id;
  for (const RunLog& run : runs) by_id[run.id] = &run;
  std::vector<std::string> ids = training_ids;
  std::sort(ids.begin(), ids.end());
  Fnv1a64 h;
  for (const std::string& id : ids) {
    h.Add(id);
    const auto it = by_id.find(id);
    if (it == by_id.end()) continue;
    const EncoderLog& e = it->second->encoders;
    h.Add(e.t_s.data(), e.t_s.size() * sizeof(double));
    h.Add(e.samples.data(), e.samples.size() * e.samples.stride() * sizeof(double));
  }
  return StrFormat("%016llx", static_cast<unsigned long long>(h.hash));
}

TrainingSplit SplitAsRecorded(const std::vector<RunLog>& logs, std::vector<AlignedRun> aligned,
                              const RecordedTraining& recorded) {
  TrainingSplit out;
  if (recorded.run_ids.empty() && !recorded.repetitions.empty()) {
    out.split = SplitByRepetition(std::move(aligned), recorded.repetitions);
    out.how = "by repetition";
    return out;
  }
  const std::set<std::string> ids(recorded.run_ids.begin(), recorded.run_ids.end());
  std::size_t present = 0;
  for (const AlignedRun& run : aligned) present += ids.count(run.id);
  const bool same_data = !ids.empty() && present == ids.size() &&
                         (recorded.fingerprint.empty() ||
                          recorded.fingerprint == TrainingFingerprint(logs, recorded.run_ids));
  for (AlignedRun& run : aligned) {
    const bool trains = same_data && ids.count(run.id) > 0;
    (trains ? out.split.training : out.split.validation).push_back(std::move(run));
  }
  out.split.training_repetitions = Repetitions(out.split.training);
  out.split.validation_repetitions = Repetitions(out.split.validation);
  out.how = same_data ? "by id" : "none";
  return out;
}

}  // namespace fitcal
