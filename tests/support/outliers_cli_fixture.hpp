#pragma once
// A short simulated pulse record (100 Hz, GL-2D-like noise) and the same record with one data line
// replaced by a spike of 10^6 pulses, for the outlier tests of the commands.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "test_support.hpp"

namespace rwcalc::test {

struct SpikedRecord {
  TempDir dir;
  std::string clean;           ///< the simulated record
  std::string spiked;          ///< the same with one spike
  std::size_t spike_line = 0;  ///< 1-based line of the spike in `spiked`
  std::size_t samples = 0;     ///< data lines of either file

  explicit SpikedRecord(double duration_s, std::uint64_t seed = 11) {
    clean = (dir.path() / "clean.csv").string();
    spiked = (dir.path() / "spiked.csv").string();
    const auto r = run_exe({"simulate", "-o", clean, "--duration", std::to_string(duration_s), "--rate", "100", "--arw",
                            "0.001", "--bias-instability", "0.005", "--seed", std::to_string(seed)});
    EXPECT_EQ(r.status, 0) << r.err;
    std::istringstream in(slurp(clean));
    std::string text, line;
    std::size_t no = 0, first_data = 0;
    while (std::getline(in, line)) {
      ++no;
      const bool data = !line.empty() && (std::isdigit(static_cast<unsigned char>(line[0])) || line[0] == '-');
      if (data && first_data == 0) first_data = no;
      if (data) ++samples;
      // The spike a third of the way in, away from the ends the detectors treat apart.
      if (data && first_data && no == first_data + static_cast<std::size_t>(duration_s * 100 / 3)) {
        line = "1000000";
        spike_line = no;
      }
      text += line + "\n";
    }
    EXPECT_GT(spike_line, 0u) << "no data line to replace in " << clean;
    std::ofstream(spiked, std::ios::binary) << text;
  }
};

}  // namespace rwcalc::test
