#include "rwcalc/sha256.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>

#include <stdexcept>

namespace rwcalc::detail {

struct Sha256::Ctx {
  EVP_MD_CTX* md = EVP_MD_CTX_new();
  ~Ctx() { EVP_MD_CTX_free(md); }
};

Sha256::Sha256() : ctx_(std::make_unique<Ctx>()) {
  if (!ctx_->md || EVP_DigestInit_ex(ctx_->md, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error(tr("SHA-256: OpenSSL could not start a digest"));
}

Sha256::~Sha256() = default;

void Sha256::update(std::string_view bytes) {
  if (!bytes.empty() && EVP_DigestUpdate(ctx_->md, bytes.data(), bytes.size()) != 1)
    throw std::runtime_error(tr("SHA-256: OpenSSL digest update failed"));
}

std::string Sha256::hex() const {
  // Finish a copy, so that the running digest can take more bytes.
  Ctx copy;
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  if (!copy.md || EVP_MD_CTX_copy_ex(copy.md, ctx_->md) != 1 || EVP_DigestFinal_ex(copy.md, digest, &len) != 1)
    throw std::runtime_error(tr("SHA-256: OpenSSL digest final failed"));
  std::string out;
  for (unsigned int i = 0; i < len; ++i) out += fmt::format("{:02x}", digest[i]);
  return out;
}

}  // namespace rwcalc::detail
