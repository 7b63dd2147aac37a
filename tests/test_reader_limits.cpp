// Hostile input and memory: a gzip bomb of NUL bytes, /dev/zero, /dev/urandom, an endless line from a
// pipe. Each is refused at its first bad chunk with the file, the line and what is wrong, and the
// process stays small: the command line runs under an address-space limit (ulimit -v) that the
// whole decompressed text would exceed, and under `timeout` so that a regression cannot hang the
// suite. A good record of long lines is read within a limit below the size of its text: memory
// follows the samples kept, not the text. Under AddressSanitizer (which reserves terabytes of
// address space) the limit is left out and only the messages are checked.
// The memory ceiling: a record whose samples would take more than it (half the address space
// rwcalc may use, or --max-memory) is refused naming the file and the memory it needs; simulate
// estimates the memory of a record before it starts and refuses one that cannot fit.
#include <sys/wait.h>
#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "io/text_source.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

// Address space allowed to the command line: far below the text these inputs decompress to.
constexpr long kLimitKiB = 512L * 1024;

std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Run `FEED | rwcalc ARGS` (or rwcalc ARGS alone) under the limit and a 20-s timeout. The commands
// run with RWCALC_THREADS=2, so that the threads' stacks and heaps do not depend on the machine's
// cores.
rwcalc::test::CliResult run_limited(const std::string& feed, const std::vector<std::string>& args,
                                    long limit_kib = kLimitKiB) {
  const rwcalc::test::TempDir tmp;
  std::string cmd;
  if (!kSanitized) cmd += "ulimit -v " + std::to_string(limit_kib) + "; ";
  if (!feed.empty()) cmd += feed + " | ";
  cmd += "RWCALC_THREADS=2 timeout 20 ";  // two worker threads' stacks under the address-space limit
  cmd += quote(RWCALC_EXE);
  for (const auto& a : args) cmd.append(" ").append(quote(a));
  cmd.append(" >").append(quote((tmp.path() / "out").string()));
  cmd.append(" 2>").append(quote((tmp.path() / "err").string()));
  const int rc = std::system(cmd.c_str());  // sh -c
  rwcalc::test::CliResult r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
  r.out = rwcalc::test::slurp(tmp.path() / "out");
  r.err = rwcalc::test::slurp(tmp.path() / "err");
  return r;
}

// gzip members of `unit` repeated `copies` times (concatenated members are one stream): a small
// file that inflates to copies × unit.size() bytes.
std::string gzip_repeated(const std::string& unit, std::size_t copies) {
  z_stream z{};
  if (deflateInit2(&z, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK) std::abort();
  std::string member(deflateBound(&z, unit.size()) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(unit.data()));
  z.avail_in = static_cast<uInt>(unit.size());
  z.next_out = reinterpret_cast<Bytef*>(member.data());
  z.avail_out = static_cast<uInt>(member.size());
  if (deflate(&z, Z_FINISH) != Z_STREAM_END) std::abort();
  member.resize(z.total_out);
  deflateEnd(&z);
  std::string out;
  out.reserve(member.size() * copies);
  for (std::size_t i = 0; i < copies; ++i) out += member;
  return out;
}

// A ~1 MB gzip file of NUL bytes that inflates to ~2 GB.
std::string zeros_bomb() { return gzip_repeated(std::string(std::size_t{2} << 20, '\0'), 1000); }

TEST(HostileInput, GzipOfNulBytesIsRefusedAtLineOneWithLittleMemory) {
  const rwcalc::test::TempDir tmp;
  const std::string bomb = zeros_bomb();
  ASSERT_LT(bomb.size(), std::size_t{3} << 20);
  const auto path = tmp.write("zeros.csv.gz", bomb).string();
  const auto r = run_limited("", {"allan", path});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("rwcalc: error: " + path + ":1: binary data (byte 0x00 at column 1)", 0), 0u) << r.err;
  // The same through a pipe (standard input: read and inflated chunk by chunk).
  const auto piped = run_limited("cat " + quote(path), {"allan", "-"});
  EXPECT_EQ(piped.status, 2) << piped.err;
  EXPECT_EQ(piped.err.rfind("rwcalc: error: <stdin>:1: binary data (byte 0x00 at column 1)", 0), 0u) << piped.err;
}

/// The error reading `text` as the file `name` gives: its line and words ("accepted", line 0, when
/// the text is read without one).
struct ReadFailure {
  std::size_t line = 0;
  std::string what = "accepted";
};
ReadFailure read_failure(const std::string& text, const char* name) {
  try {
    (void)rwcalc::read_recording_text(text, name);
  } catch (const rwcalc::InputError& e) {
    return {e.line(), e.what()};
  }
  return {};
}

TEST(HostileInput, GzipOfNulBytesAfterGoodLinesNamesTheirLine) {
  // Good lines first, then the NUL bytes in a later member: the line and column of the first one.
  const std::string head = "pulses\n1\n2\n3";
  const std::string text = gzip_repeated(head, 1) + gzip_repeated(std::string(std::size_t{1} << 20, '\0'), 200);
  const ReadFailure f = read_failure(text, "mem.gz");
  EXPECT_EQ(f.line, 4u) << f.what;
  EXPECT_NE(f.what.find("binary data (byte 0x00 at column 2)"), std::string::npos) << f.what;
}

TEST(HostileInput, ABadLineIsNamedBeforeBinaryDataInThePieceReadAheadOfIt) {
  // The next piece is read (and checked) while this one is parsed: a bad line here is still the
  // error, not the binary data of the piece after it.
  std::string text = "pulses\n";
  for (int i = 0; i < 40000; ++i) text += "1\n";
  text += "abc\n";                                                         // line 40002
  while (text.size() < rwcalc::detail::kPieceBytes + 1000) text += "2\n";  // the NULs in the second piece
  text += std::string(1000, '\0');
  const ReadFailure bad_line = read_failure(text, "mem.csv");
  EXPECT_EQ(bad_line.line, 40002u) << bad_line.what;
  EXPECT_EQ(bad_line.what.find("binary data"), std::string::npos) << bad_line.what;
  // Without the bad line, the binary data are the error.
  text.replace(text.find("abc"), 3, "1\n1");
  const ReadFailure binary = read_failure(text, "mem.csv");
  EXPECT_NE(binary.what.find("binary data"), std::string::npos) << binary.what;
}

TEST(HostileInput, DevZeroAndDevUrandomEndQuicklyWithBinaryData) {
  for (const std::string dev : {"/dev/zero", "/dev/urandom"}) {
    const auto r = run_limited("", {"allan", dev});
    EXPECT_EQ(r.status, 2) << dev << ": " << r.err;
    EXPECT_EQ(r.err.rfind("rwcalc: error: " + dev + ":", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("binary data (byte 0x"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
  const auto piped = run_limited("cat /dev/zero", {"allan", "-"});
  EXPECT_EQ(piped.status, 2) << piped.err;
  EXPECT_EQ(piped.err.rfind("rwcalc: error: <stdin>:1: binary data (byte 0x00 at column 1)", 0), 0u) << piped.err;
}

TEST(HostileInput, AnEndlessLineIsRefusedAsSoonAsItPassesTheLimit) {
  // A pipe that never sends a line end, and a gzip file of one 2-GB line.
  const auto piped = run_limited("{ printf 'pulses\\n1\\n'; tr '\\000' 7 </dev/zero; }", {"allan", "-"});
  EXPECT_EQ(piped.status, 2) << piped.err;
  EXPECT_EQ(piped.err.rfind("rwcalc: error: <stdin>:3: line too long", 0), 0u) << piped.err;
  const rwcalc::test::TempDir tmp;
  const auto path = tmp.write("line.csv.gz", gzip_repeated(std::string(std::size_t{2} << 20, '7'), 1000)).string();
  const auto r = run_limited("", {"allan", path});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("rwcalc: error: " + path + ":1: line too long", 0), 0u) << r.err;
}

TEST(HostileInput, AGoodRecordFromAPipeIsReadWhole) {
  // Many chunks of a pipe, plain and gzip: every sample arrives (the checks drop nothing).
  std::string text = "# rate_hz: 100\npulses\n";
  for (int i = 0; i < 200000; ++i) text += std::to_string(i % 3) + "\n";
  const rwcalc::test::TempDir tmp;
  const auto plain = tmp.write("p.txt", text).string();
  const auto gz = tmp.write("p.txt.gz", gzip_repeated(text, 1)).string();
  for (const auto& path : {plain, gz}) {
    const auto r = run_limited("cat " + quote(path), {"allan", "-"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("200000"), std::string::npos) << r.out.substr(0, 400);
  }
}

TEST(HostileInput, MemoryFollowsTheSamplesNotTheText) {
  // 200 MB of text, 200 000 samples: each line a pulse count and a note of 1000 characters. Read
  // under an address-space limit of 128 MiB, below the size of the text.
  if (kSanitized) GTEST_SKIP() << "sanitizers reserve address space: no limit to test against";
  const rwcalc::test::TempDir tmp;
  const auto path = (tmp.path() / "long_lines.csv").string();
  {
    std::ofstream out(path, std::ios::binary);
    out << "# rate_hz: 400\npulses,note\n";
    const std::string note(1000, 'n');
    std::string block;
    for (int i = 0; i < 200000; ++i) {
      block += std::to_string(i % 3) + "," + note + "\n";
      if (block.size() > (std::size_t{1} << 22)) out << block, block.clear();
    }
    out << block;
  }
  ASSERT_GT(std::filesystem::file_size(path), std::size_t{180} << 20);  // 191 MiB
  const auto r = run_limited("", {"allan", path}, 128L * 1024);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("200000"), std::string::npos) << r.out.substr(0, 400);
}

// ---- The memory ceiling -------------------------------------------------------------------------

// A gzip file of good lines, "0\n1\n" over and over: 1 MB that inflates to 1 GiB of text, 2^29
// samples, 4 GiB to keep as 64-bit pulse counts.
std::string good_lines_bomb() {
  std::string unit;
  for (int i = 0; i < (1 << 20); ++i) unit += "0\n1\n";
  return gzip_repeated(unit, 256);
}

// The memory a refusal names ("needs about 4.01 GiB"), in MiB; 0 when there is none.
double needed_mib(const std::string& message) {
  std::smatch m;
  if (!std::regex_search(message, m, std::regex("needs about ([0-9.]+) (KiB|MiB|GiB|TiB)"))) return 0;
  const double unit = m[2] == "KiB" ? 1.0 / 1024 : m[2] == "MiB" ? 1 : m[2] == "GiB" ? 1024 : 1024 * 1024;
  return std::stod(m[1]) * unit;
}

TEST(MemoryCeiling, AGzipOfGoodLinesStopsAtTheCeilingNamingTheFileAndTheMemoryNeeded) {
  const rwcalc::test::TempDir tmp;
  const std::string bomb = good_lines_bomb();
  ASSERT_LT(bomb.size(), std::size_t{2} << 20);
  const auto path = tmp.write("lines.csv.gz", bomb).string();
  // --max-memory sets the ceiling: the samples stop at it, and the memory the whole record needs
  // is judged from the file's size.
  auto r = run_limited("", {"analyze", path, "--max-memory", "64M"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("rwcalc: error: " + path + ":", 0), 0u) << r.err;
  EXPECT_NEAR(needed_mib(r.err), 4096, 200) << r.err;  // judged from a part of the file
  EXPECT_NE(r.err.find("memory ceiling of 64 MiB (--max-memory)"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
  // From a pipe the size is unknown: the record needs more than the ceiling.
  r = run_limited("cat " + quote(path), {"analyze", "-", "--max-memory", "64M"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("rwcalc: error: <stdin>:", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("needs more than 64 MiB"), std::string::npos) << r.err;
  // Without the option the ceiling is half the address space rwcalc may use: under ulimit -v of
  // 512 MiB, 256 MiB; the file ends with status 2, not "out of memory".
  if (!kSanitized) {
    r = run_limited("", {"analyze", path});
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("rwcalc: error: " + path + ":", 0), 0u) << r.err;
    EXPECT_NEAR(needed_mib(r.err), 4096, 200) << r.err;  // judged from a part of the file
    EXPECT_NE(r.err.find("memory ceiling of 256 MiB (half the address-space limit"), std::string::npos) << r.err;
  }
  // A record within the ceiling is read whole: 2^20 samples (8 MiB of counts) under 16 MiB.
  std::string unit;
  for (int i = 0; i < (1 << 19); ++i) unit += "0\n1\n";
  const auto fits = tmp.write("fits.csv", unit).string();
  r = run_limited("", {"allan", fits, "--max-memory", "16M"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1048576"), std::string::npos) << r.out.substr(0, 400);
}

TEST(MemoryCeiling, SimulateEstimatesTheFlickerMemoryAndRefusesWhatCannotFit) {
  const rwcalc::test::TempDir tmp;
  const auto out = (tmp.path() / "day.csv").string();
  // 10 days at 1 kHz with bias instability: its flicker term is one FFT over twice the record, held
  // in place as floats, 8 bytes per sample, some 6.4 GiB. Under ulimit -v 4000000 (or a ceiling of 1 GiB) it is refused
  // before anything is written, naming the option and the memory.
  const std::vector<std::string> day{"simulate",           "-o",  out, "--duration", "864000", "--rate", "1000",
                                     "--bias-instability", "0.01"};
  auto r =
      kSanitized ? run_limited("", rwcalc::test::concat(day, {"--max-memory", "1G"})) : run_limited("", day, 4000000);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--bias-instability"), std::string::npos) << r.err;
  EXPECT_GT(needed_mib(r.err), 6 * 1024) << r.err;
  EXPECT_LT(needed_mib(r.err), 7 * 1024) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The estimate is what the record takes: 2·10^6 samples run within an address-space limit of
  // the estimate plus 64 MiB for the program itself (with the ceiling raised to the estimate).
  const std::vector<std::string> small{"simulate",           "-o",  out, "--duration", "20000", "--rate", "100",
                                       "--bias-instability", "0.01"};
  r = run_limited("", rwcalc::test::concat(small, {"--max-memory", "1M"}));
  EXPECT_EQ(r.status, 2) << r.err;
  const double mib = needed_mib(r.err);
  EXPECT_GT(mib, 15) << r.err;
  EXPECT_LT(mib, 20) << r.err;
  if (!kSanitized) {
    const std::string ceiling = fmt::format("{:.0f}M", std::ceil(mib) + 1);
    r = run_limited("", rwcalc::test::concat(small, {"--max-memory", ceiling}), static_cast<long>((mib + 64) * 1024));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(std::filesystem::exists(out));
  }
}

}  // namespace
