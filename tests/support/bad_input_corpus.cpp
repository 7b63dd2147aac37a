#include "bad_input_corpus.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rwcalc::test {

void PrintTo(const BadInputCase& c, std::ostream* os) { *os << c.file << " [" << c.options << "]"; }

std::vector<BadInputCase> load_bad_input_manifest() {
  std::vector<BadInputCase> cases;
  std::ifstream in(source_path("tests/bad_input/MANIFEST.tsv"));
  std::string row;
  while (std::getline(in, row)) {
    if (row.empty() || row[0] == '#') continue;
    std::vector<std::string> f;
    std::stringstream ss(row);
    for (std::string cell; std::getline(ss, cell, '\t');) f.push_back(cell);
    if (f.size() != 5) throw std::runtime_error("MANIFEST.tsv: bad row: " + row);
    cases.push_back({f[0], f[1], std::stoi(f[2]), f[3], static_cast<std::size_t>(std::stoul(f[4]))});
  }
  return cases;
}

std::optional<std::string> stage_bad_input(const BadInputCase& c, const TempDir& tmp) {
  // A line of a megabyte, just within the reader's limit (1 MiB: 1048576 bytes), and one byte past it.
  constexpr std::size_t kHuge = 1'048'000;
  constexpr std::size_t kOverlong = 1'048'577;
  if (c.file == "@missing") return (tmp.path() / "no-such-recording.csv").string();
  if (c.file == "@directory") return tmp.path().string();
  if (c.file == "@unreadable") {
    if (::geteuid() == 0) return std::nullopt;  // permissions do not stop root from reading
    const auto path = tmp.write("locked.csv", "1\n2\n").string();
    ::chmod(path.c_str(), 0);
    return path;
  }
  if (c.file == "@huge_digit_line")
    return tmp.write("digits.csv", "pulses\n1\n" + std::string(kHuge, '7') + "\n2\n").string();
  if (c.file == "@huge_float_line")
    return tmp.write("float.csv", "rate\n0.5\n1" + std::string(kHuge, '0') + ".5\n2\n").string();
  if (c.file == "@huge_text_line")
    return tmp.write("text.csv", "pulses\n1\n" + std::string(kHuge, 'x') + "\n2\n").string();
  if (c.file == "@huge_header_line") return tmp.write("header.csv", std::string(kHuge, 'h') + "\n").string();
  if (c.file == "@overlong_digit_line")
    return tmp.write("long-digits.csv", "pulses\n1\n" + std::string(kOverlong, '7') + "\n2\n").string();
  if (c.file == "@overlong_comment_line")
    return tmp.write("long-comment.csv", "# " + std::string(kOverlong, 'c') + "\npulses\n1\n2\n").string();
  if (c.file == "@overlong_crlf_line")
    return tmp.write("long-crlf.csv", "pulses\r\n1\r\n2\r\n" + std::string(kOverlong, 'x') + "\r\n").string();
  if (c.file == "@overlong_cr_line")
    return tmp.write("long-cr.csv", "pulses\r1\r" + std::string(kOverlong, '5') + "\r2\r").string();
  return source_path("tests/bad_input/" + c.file).string();
}

std::string bad_input_case_name(const ::testing::TestParamInfo<BadInputCase>& info) {
  std::string n;
  for (char ch : info.param.file) n += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  return n;
}

}  // namespace rwcalc::test
