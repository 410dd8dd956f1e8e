#pragma once
/// \file TlsContext.hpp
/// The server's TLS settings for --tls-cert/--tls-key: the certificate chain and key (PEM), TLS 1.2
/// or newer, OpenSSL's default ciphers. For sites without a reverse proxy; docs/deploy.md says when a
/// proxy is the better choice.

#include <boost/asio/ssl/context.hpp>
#include <filesystem>
#include <memory>
#include <string>

namespace rcfd::server {

/// Loads `certificate` (a PEM chain, the server's certificate first) and its unencrypted PEM private
/// `key`. Throws std::runtime_error naming the option and file that cannot be used, or saying that
/// the key is not the certificate's. `warning` is set when the key file is readable by its group or
/// others.
std::unique_ptr<boost::asio::ssl::context> serverTlsContext(const std::filesystem::path& certificate,
                                                            const std::filesystem::path& key,
                                                            std::string& warning);

}  // namespace rcfd::server
