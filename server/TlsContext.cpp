#include "TlsContext.hpp"

#include <openssl/ssl.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace rcfd::server {

namespace net = boost::asio;

namespace {

void requireReadable(const std::filesystem::path& file, const char* option) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(std::string(option) + " " + file.string() + ": cannot read: " + std::strerror(errno));
}

}  // namespace

std::unique_ptr<net::ssl::context> serverTlsContext(const std::filesystem::path& certificate,
                                                    const std::filesystem::path& key, std::string& warning) {
  requireReadable(certificate, "--tls-cert");
  requireReadable(key, "--tls-key");
  auto context = std::make_unique<net::ssl::context>(net::ssl::context::tls_server);
  context->set_options(net::ssl::context::default_workarounds | net::ssl::context::no_sslv2 |
                       net::ssl::context::no_sslv3 | net::ssl::context::no_tlsv1 |
                       net::ssl::context::no_tlsv1_1 | net::ssl::context::single_dh_use);
  if (SSL_CTX_set_min_proto_version(context->native_handle(), TLS1_2_VERSION) != 1)
    throw std::runtime_error("OpenSSL refuses TLS 1.2 as the minimum version");
  // OpenSSL would ask for the pass phrase of an encrypted key on the terminal, which a service has
  // not: an encrypted key fails at once instead.
  context->set_password_callback([](std::size_t, net::ssl::context::password_purpose) { return std::string(); });
  // The key before the certificate: OpenSSL refuses a key that does not match a certificate already
  // loaded with a bare "key values mismatch", but takes a certificate after its key either way, and
  // the check below says which file is whose.
  boost::system::error_code ec;
  context->use_private_key_file(key.string(), net::ssl::context::pem, ec);
  if (ec)
    throw std::runtime_error("--tls-key " + key.string() + ": not an unencrypted PEM private key (" +
                             ec.message() + ")");
  context->use_certificate_chain_file(certificate.string(), ec);
  if (ec)
    throw std::runtime_error("--tls-cert " + certificate.string() + ": not a PEM certificate chain (" +
                             ec.message() + ")");
  if (SSL_CTX_check_private_key(context->native_handle()) != 1)
    throw std::runtime_error("--tls-key " + key.string() + " is not the key of --tls-cert " + certificate.string());
  struct stat st {};
  if (::stat(key.c_str(), &st) == 0 && (st.st_mode & (S_IRGRP | S_IROTH))) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    warning = "TLS key " + key.string() + " is readable by its group or others (mode " + mode + "); chmod 600 " +
              key.string();
  }
  return context;
}

}  // namespace rcfd::server
