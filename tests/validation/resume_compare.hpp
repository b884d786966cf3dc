// Comparison of an interrupted-and-resumed run with an uninterrupted one: series.csv, cracks.csv
// and summary.json must be byte for byte the same, apart from the timings in summary.json
// (wall_time_s, mlups and any key ending in _seconds or _wall_share), which measure the machine, not the run.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace ff::test {

inline std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// summary.json without its timings, as text (so a difference shows in the failure message).
inline std::string summary_without_timings(const std::filesystem::path& dir) {
  auto j = nlohmann::json::parse(read_bytes(dir / "summary.json"));
  std::function<void(nlohmann::json&)> strip = [&](nlohmann::json& x) {
    if (!x.is_object()) return;
    for (auto it = x.begin(); it != x.end();) {
      const std::string& k = it.key();
      auto ends = [&](const std::string& e) { return k.size() > e.size() && k.compare(k.size() - e.size(), e.size(), e) == 0; };
      const bool timing = k == "wall_time_s" || k == "mlups" || ends("_seconds") || ends("_wall_share");
      if (timing) it = x.erase(it);
      else strip(*it++);
    }
  };
  strip(j);
  return j.dump(1);
}

// The first line where two texts differ, as "whole | resumed".
inline std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string la, lb;
  while (true) {
    const bool ga = static_cast<bool>(std::getline(sa, la)), gb = static_cast<bool>(std::getline(sb, lb));
    if (!ga && !gb) return "(no difference)";
    if (!ga || !gb || la != lb) return (ga ? la : "(end)") + " | " + (gb ? lb : "(end)");
  }
}

// Every result file of `resumed` equals that of `whole` (cracks.csv where the driver writes one).
inline void expect_same_results(const std::filesystem::path& whole, const std::filesystem::path& resumed,
                                const std::string& what) {
  ASSERT_TRUE(std::filesystem::exists(resumed / "summary.json")) << what;
  EXPECT_TRUE(read_bytes(whole / "series.csv") == read_bytes(resumed / "series.csv")) << what << ": series.csv differs";
  if (std::filesystem::exists(whole / "cracks.csv")) {
    EXPECT_TRUE(read_bytes(whole / "cracks.csv") == read_bytes(resumed / "cracks.csv")) << what << ": cracks.csv differs";
  }
  const std::string a = summary_without_timings(whole), b = summary_without_timings(resumed);
  EXPECT_TRUE(a == b) << what << ": summary.json differs first at\n  " << first_difference(a, b);
}

}  // namespace ff::test
