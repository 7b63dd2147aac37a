// The SHA-256 that identifies input files: the standard's test vectors, piecewise feeding, and a
// recording's digest as the reader's byte source computes it, equal to `sha256sum` of the file
// (for gzip, of the compressed bytes as stored).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/text_source.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/sha256.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

std::string digest_of(std::string_view s) {
  detail::Sha256 h;
  h.update(s);
  return h.hex();
}

TEST(Sha256, StandardVectorsAndPieces) {
  EXPECT_EQ(digest_of(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(digest_of("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const std::string two_blocks = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  EXPECT_EQ(digest_of(two_blocks), "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  detail::Sha256 pieces;
  for (char c : two_blocks) pieces.update(std::string_view(&c, 1));
  EXPECT_EQ(pieces.hex(), digest_of(two_blocks));
  EXPECT_EQ(pieces.hex(), pieces.hex());  // reading the digest does not end the stream
}

/// `sha256sum FILE`'s digest, or empty when the tool is absent.
std::string sha256sum(const std::filesystem::path& f) {
  std::FILE* p = ::popen(("sha256sum '" + f.string() + "' 2>/dev/null").c_str(), "r");
  if (!p) return {};
  std::array<char, 65> buf{};
  const std::size_t n = std::fread(buf.data(), 1, 64, p);
  ::pclose(p);
  return n == 64 ? std::string(buf.data(), 64) : std::string();
}

TEST(Sha256, RecordingDigestEqualsSha256sumOfTheStoredBytes) {
  const auto gz = std::filesystem::path(RWCALC_SOURCE_DIR) / "data/gl2d/gl2d_0C.csv.gz";
  if (!std::filesystem::exists(gz)) GTEST_SKIP() << "shipped recording absent: " << gz;
  test::TempDir dir;
  const auto text = dir.write("run.csv", "# rate_hz: 400\npulses\n1\n-2\n3\n");
  for (const auto& f : {gz, text}) {
    detail::TextSource src(f.string());
    std::string out;
    while (src.read(out)) out.clear();
    EXPECT_EQ(src.raw_bytes(), std::filesystem::file_size(f)) << f;
    std::ifstream in(f, std::ios::binary);
    std::stringstream whole;
    whole << in.rdbuf();
    EXPECT_EQ(src.sha256(), digest_of(whole.str())) << f;
    const Recording rec = read_recording(f.string());  // what the outputs report
    EXPECT_EQ(rec.sha256, src.sha256()) << f;
    EXPECT_EQ(rec.file_bytes, std::filesystem::file_size(f)) << f;
    if (const std::string tool = sha256sum(f); !tool.empty()) {
      EXPECT_EQ(src.sha256(), tool) << f;
    }
  }
}

}  // namespace
}  // namespace rwcalc
