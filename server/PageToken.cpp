#include "PageToken.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>
#include <sys/stat.h>

#include <fstream>
#include <iterator>
#include <stdexcept>

#include "Ids.hpp"

namespace rcfd::server {
namespace {

constexpr std::size_t kKeyBytes = 32;

std::string hmac(const std::string& key, const std::string& data) {
  unsigned char out[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (!HMAC(EVP_sha256(), key.data(), int(key.size()), reinterpret_cast<const unsigned char*>(data.data()),
            data.size(), out, &length))
    throw std::runtime_error("HMAC-SHA256 failed");
  return std::string(reinterpret_cast<const char*>(out), length);
}

}  // namespace

std::string pageTokenKey(const std::filesystem::path& dataDir) {
  const auto path = dataDir / "page-token.key";
  {
    std::ifstream in(path, std::ios::binary);
    std::string key((std::istreambuf_iterator<char>(in)), {});
    if (in && key.size() == kKeyBytes) return key;
  }
  std::string key(kKeyBytes, '\0');
  if (RAND_bytes(reinterpret_cast<unsigned char*>(key.data()), int(key.size())) != 1)
    throw std::runtime_error("no random bytes for the page-token key");
  const auto temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(key.data(), std::streamsize(key.size()));
    if (!out) throw std::runtime_error("cannot write " + temporary);
  }
  ::chmod(temporary.c_str(), 0600);
  std::filesystem::rename(temporary, path);
  return key;
}

std::string signPageToken(const nlohmann::json& payload, const std::string& key) {
  const std::string body = payload.dump();
  return base64UrlEncode(body) + "." + base64UrlEncode(hmac(key, body));
}

std::optional<nlohmann::json> verifyPageToken(const std::string& token, const std::string& key) {
  const auto dot = token.find('.');
  if (dot == std::string::npos) return std::nullopt;
  const auto body = base64UrlDecode(std::string_view(token).substr(0, dot));
  const auto signature = base64UrlDecode(std::string_view(token).substr(dot + 1));
  if (!body || !signature) return std::nullopt;
  const std::string expected = hmac(key, *body);
  if (signature->size() != expected.size() || CRYPTO_memcmp(signature->data(), expected.data(), expected.size()) != 0)
    return std::nullopt;
  auto payload = nlohmann::json::parse(*body, nullptr, false);
  if (payload.is_discarded()) return std::nullopt;
  return payload;
}

}  // namespace rcfd::server
