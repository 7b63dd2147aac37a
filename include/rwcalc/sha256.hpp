#pragma once
// SHA-256 of a byte stream, fed piece by piece (OpenSSL's implementation): identifies an input file
// in a test report exactly as `sha256sum` does.
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

namespace rwcalc::detail {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  void update(std::string_view bytes);
  /// The digest of everything fed so far, as 64 lower-case hex digits (feeding may go on).
  [[nodiscard]] std::string hex() const;

 private:
  struct Ctx;
  std::unique_ptr<Ctx> ctx_;
};

}  // namespace rwcalc::detail
