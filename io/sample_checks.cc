#include "io/sample_checks.h"

#include <map>
#include <mutex>

namespace fitcal::io {
namespace {

std::mutex g_mutex;
std::map<std::string, SampleCheck>& Checks() {
  static std::map<std::string, SampleCheck> checks;
  return checks;
}

}  // namespace

void RegisterSampleCheck(const std::string& model, SampleCheck check) {
  const std::lock_guard<std::mutex> lock(g_mutex);
  Checks()[model] = check;
}

void RunSampleCheck(const std::string& model, const EncoderLog& log, const std::string& path) {
  SampleCheck check = nullptr;
  {
    const std::lock_guard<std::mutex> lock(g_mutex);
    const auto it = Checks().find(model);
    if (it != Checks().end()) check = it->second;
  }
  if (check != nullptr) check(log, path);
}

}  // namespace fitcal::io
