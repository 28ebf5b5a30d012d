#include "io/manifest.hpp"

#include <unistd.h>

#include <array>
#include <chrono>
#include <ctime>
#include <fstream>
#include <string_view>
#include <thread>

#include "core/build_info.hpp"

namespace caplab::io {

namespace {

std::string trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(first, last - first + 1));
}

}  // namespace

std::string utc_now_iso8601() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::array<char, 32> buf{};
  const std::size_t n = std::strftime(buf.data(), buf.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return std::string(buf.data(), n);
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  // x86 names the CPU in "model name"; some ARM kernels only give "Hardware" or "Processor".
  for (const char* key : {"model name", "Hardware", "Processor"}) {
    in.clear();
    in.seekg(0);
    while (std::getline(in, line)) {
      const auto colon = line.find(':');
      if (colon == std::string::npos) continue;
      if (trim(std::string_view(line).substr(0, colon)) == key) {
        std::string value = trim(std::string_view(line).substr(colon + 1));
        if (!value.empty()) return value;
      }
    }
  }
  return "unknown";
}

std::string host_name() {
  std::array<char, 256> buf{};
  if (gethostname(buf.data(), buf.size() - 1) != 0) return "unknown";
  return std::string(buf.data());
}

nlohmann::json environment_json(int threads) {
  const core::BuildInfo& b = core::build_info();
  return {
      {"build",
       {{"version", std::string(b.version)},
        {"git_sha", std::string(b.git_sha)},
        {"git_dirty", b.git_dirty},
        {"compiler", std::string(b.compiler)},
        {"flags", std::string(b.flags)},
        {"build_type", std::string(b.build_type)}}},
      {"host", host_name()},
      {"cpu_model", cpu_model()},
      {"hardware_threads", std::thread::hardware_concurrency()},
      {"threads", threads},
      {"date_utc", utc_now_iso8601()},
  };
}

}  // namespace caplab::io
