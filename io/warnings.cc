#include "io/warnings.h"

#include <cstdio>
#include <mutex>
#include <utility>

#include "io/input_error.h"

namespace fitcal::io {

namespace {
std::mutex& SinkMutex() {
  static std::mutex mutex;
  return mutex;
}
std::function<void(const std::string&)>& Sink() {
  static std::function<void(const std::string&)> sink;
  return sink;
}
}  // namespace

void Warn(const std::string& file, int line, const std::string& message) {
  const std::string text = FileLineText(file, line, message);
  std::lock_guard<std::mutex> lock(SinkMutex());
  if (Sink()) {
    Sink()(text);
  } else {
    std::fprintf(stderr, "fitcal: warning: %s\n", text.c_str());
  }
}

void SetWarningSinkForTests(std::function<void(const std::string&)> sink) {
  std::lock_guard<std::mutex> lock(SinkMutex());
  Sink() = std::move(sink);
}

}  // namespace fitcal::io
