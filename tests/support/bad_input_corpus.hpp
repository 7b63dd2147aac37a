#pragma once
// The bad-input corpus (tests/bad_input/MANIFEST.tsv), shared by the reader test and the CLI test.
#include <cstddef>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace rwcalc::test {

/// One row of MANIFEST.tsv: file, input options, expected exit status, message fragment, line.
struct BadInputCase {
  std::string file, options;
  int status = 0;
  std::string fragment;
  std::size_t line = 0;
};

void PrintTo(const BadInputCase& c, std::ostream* os);

/// Every row of the manifest (throws on a malformed row).
std::vector<BadInputCase> load_bad_input_manifest();

/// The path a case reads: a committed file, or for "@…" cases one made in `tmp` (a missing path, a
/// directory, an unreadable file, lines of megabytes). Empty when the case cannot be staged here
/// (an unreadable file when running as root).
std::optional<std::string> stage_bad_input(const BadInputCase& c, const TempDir& tmp);

/// A test name made of the case's file name.
std::string bad_input_case_name(const ::testing::TestParamInfo<BadInputCase>& info);

}  // namespace rwcalc::test
