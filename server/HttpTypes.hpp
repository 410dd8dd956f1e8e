#pragma once
/// \file HttpTypes.hpp
/// The message types the server speaks: requests with a string body (JSON, limited size), responses
/// with a string body (JSON, text) or a file body (artifacts, streamed from disk).

#include <boost/beast/http.hpp>
#include <variant>

namespace rcfd::server {

namespace http = boost::beast::http;

using Request = http::request<http::string_body>;
using StringResponse = http::response<http::string_body>;
using FileResponse = http::response<http::file_body>;
using Response = std::variant<StringResponse, FileResponse>;

}  // namespace rcfd::server
