#pragma once
// SHA-256 over a stream of bytes, through OpenSSL's libcrypto (EVP interface): the content
// address of an uploaded asset.
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

namespace penumbra::server {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void update(const char* data, std::size_t size);
  // The digest as 64 lowercase hex digits; the object is spent afterwards.
  std::string hex_digest();

 private:
  struct Context;
  std::unique_ptr<Context> ctx_;
};

std::string sha256_hex(std::string_view bytes);

}  // namespace penumbra::server
