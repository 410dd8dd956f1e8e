#include "core/Svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/AxisTicks.hpp"
#include "core/Errors.hpp"

namespace rcfd {
namespace {
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}
std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}
}  // namespace

std::string Rgb::hex() const {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", r, g, b);
  return buf;
}

Rgb colormap(double value) {
  // Anchor points of matplotlib's viridis, linearly interpolated.
  static const std::array<std::array<double, 3>, 9> anchors{{{68, 1, 84},
                                                             {71, 44, 122},
                                                             {59, 81, 139},
                                                             {44, 113, 142},
                                                             {33, 144, 141},
                                                             {39, 173, 129},
                                                             {92, 200, 99},
                                                             {170, 220, 50},
                                                             {253, 231, 37}}};
  const double v = std::isfinite(value) ? std::clamp(value, 0.0, 1.0) : 0.0;
  const double s = v * (anchors.size() - 1);
  const std::size_t i = std::min<std::size_t>(std::size_t(s), anchors.size() - 2);
  const double f = s - double(i);
  Rgb c;
  c.r = static_cast<unsigned char>(std::lround(anchors[i][0] + f * (anchors[i + 1][0] - anchors[i][0])));
  c.g = static_cast<unsigned char>(std::lround(anchors[i][1] + f * (anchors[i + 1][1] - anchors[i][1])));
  c.b = static_cast<unsigned char>(std::lround(anchors[i][2] + f * (anchors[i + 1][2] - anchors[i][2])));
  return c;
}

SvgDocument::SvgDocument(double xmin, double xmax, double ymin, double ymax, double widthPx,
                         double heightPx, double marginPx)
    : xmin_(xmin), xmax_(xmax), ymin_(ymin), ymax_(ymax), width_(widthPx), height_(heightPx),
      margin_(marginPx) {}

double SvgDocument::px(double x) const {
  return margin_ + (x - xmin_) / (xmax_ - xmin_) * (width_ - 2 * margin_);
}
double SvgDocument::py(double y) const {
  return height_ - margin_ - (y - ymin_) / (ymax_ - ymin_) * (height_ - 2 * margin_);
}

void SvgDocument::line(double x0, double y0, double x1, double y1, const std::string& stroke,
                       double widthPx, const std::string& dash) {
  body_ += "<line x1=\"" + num(px(x0)) + "\" y1=\"" + num(py(y0)) + "\" x2=\"" + num(px(x1)) +
           "\" y2=\"" + num(py(y1)) + "\" stroke=\"" + stroke + "\" stroke-width=\"" + num(widthPx) +
           "\"" + (dash.empty() ? "" : " stroke-dasharray=\"" + dash + "\"") + "/>\n";
}

void SvgDocument::translucentLine(double x0, double y0, double x1, double y1, const std::string& stroke,
                                  double widthPx, double opacity, const std::string& dash) {
  body_ += "<line x1=\"" + num(px(x0)) + "\" y1=\"" + num(py(y0)) + "\" x2=\"" + num(px(x1)) +
           "\" y2=\"" + num(py(y1)) + "\" stroke=\"" + stroke + "\" stroke-width=\"" + num(widthPx) +
           "\" stroke-opacity=\"" + num(opacity) + "\"" +
           (dash.empty() ? "" : " stroke-dasharray=\"" + dash + "\"") + "/>\n";
}

void SvgDocument::polyline(const std::vector<std::array<double, 2>>& points, const std::string& stroke,
                           double widthPx) {
  body_ += "<polyline fill=\"none\" stroke=\"" + stroke + "\" stroke-width=\"" + num(widthPx) +
           "\" points=\"";
  for (const auto& p : points) body_ += num(px(p[0])) + "," + num(py(p[1])) + " ";
  body_ += "\"/>\n";
}

void SvgDocument::polygon(const std::vector<std::array<double, 2>>& points, const std::string& fill,
                          const std::string& stroke, double widthPx, double opacity) {
  body_ += "<polygon fill=\"" + fill + "\" fill-opacity=\"" + num(opacity) + "\" stroke=\"" + stroke +
           "\" stroke-width=\"" + num(widthPx) + "\" points=\"";
  for (const auto& p : points) body_ += num(px(p[0])) + "," + num(py(p[1])) + " ";
  body_ += "\"/>\n";
}

void SvgDocument::rect(double x0, double y0, double x1, double y1, const std::string& fill,
                       const std::string& stroke, double widthPx, double opacity) {
  const double left = std::min(px(x0), px(x1)), top = std::min(py(y0), py(y1));
  body_ += "<rect x=\"" + num(left) + "\" y=\"" + num(top) + "\" width=\"" +
           num(std::abs(px(x1) - px(x0))) + "\" height=\"" + num(std::abs(py(y1) - py(y0))) +
           "\" fill=\"" + fill + "\" fill-opacity=\"" + num(opacity) + "\" stroke=\"" + stroke +
           "\" stroke-width=\"" + num(widthPx) + "\"/>\n";
}

void SvgDocument::circle(double x, double y, double radiusPx, const std::string& fill) {
  body_ += "<circle cx=\"" + num(px(x)) + "\" cy=\"" + num(py(y)) + "\" r=\"" + num(radiusPx) +
           "\" fill=\"" + fill + "\"/>\n";
}

void SvgDocument::text(double x, double y, const std::string& t, double sizePx,
                       const std::string& anchor, const std::string& fill) {
  body_ += "<text x=\"" + num(px(x)) + "\" y=\"" + num(py(y)) + "\" font-size=\"" + num(sizePx) +
           "\" font-family=\"sans-serif\" text-anchor=\"" + anchor + "\" fill=\"" + fill + "\">" +
           escape(t) + "</text>\n";
}

void SvgDocument::textPx(double xPx, double yPx, const std::string& t, double sizePx,
                         const std::string& anchor) {
  body_ += "<text x=\"" + num(xPx) + "\" y=\"" + num(yPx) + "\" font-size=\"" + num(sizePx) +
           "\" font-family=\"sans-serif\" text-anchor=\"" + anchor + "\">" + escape(t) + "</text>\n";
}

void SvgDocument::heatmap(const std::vector<double>& values, int nx, int ny, double x0, double x1,
                          double y0, double y1) {
  const double dx = (x1 - x0) / nx, dy = (y1 - y0) / ny;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double v = values[std::size_t(j) * nx + i];
      if (std::isnan(v)) continue;
      // Cells overlap by a hair so no white seams appear between them in viewers.
      const double l = px(x0 + i * dx), r = px(x0 + (i + 1) * dx);
      const double t = py(y0 + (j + 1) * dy), b = py(y0 + j * dy);
      body_ += "<rect x=\"" + num(l) + "\" y=\"" + num(t) + "\" width=\"" + num(r - l + 0.3) +
               "\" height=\"" + num(b - t + 0.3) + "\" fill=\"" + colormap(v).hex() + "\"/>\n";
    }
  }
}

namespace {
// A PNG file (RGB, 8 bit) with the image data in stored (uncompressed) deflate blocks: no zlib needed.
std::string pngStored(const std::vector<unsigned char>& rgb, int width, int height) {
  auto crc32 = [](const std::string& bytes) {
    std::uint32_t c = 0xffffffffu;
    for (unsigned char b : bytes) {
      c ^= b;
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
  };
  auto be32 = [](std::string& out, std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(char((v >> s) & 0xff));
  };
  auto chunk = [&](std::string& out, const char* type, const std::string& data) {
    be32(out, std::uint32_t(data.size()));
    const std::string body = std::string(type, 4) + data;
    out += body;
    be32(out, crc32(body));
  };
  std::string raw;  // each row: filter byte 0, then RGB
  for (int y = 0; y < height; ++y) {
    raw.push_back('\0');
    raw.append(reinterpret_cast<const char*>(rgb.data()) + std::size_t(y) * width * 3, std::size_t(width) * 3);
  }
  std::string z = "\x78\x01";
  for (std::size_t pos = 0; pos < raw.size() || pos == 0; pos += 65535) {
    const std::size_t len = std::min<std::size_t>(65535, raw.size() - pos);
    z.push_back(pos + len >= raw.size() ? '\x01' : '\x00');
    z.push_back(char(len & 0xff)), z.push_back(char(len >> 8));
    z.push_back(char(~len & 0xff)), z.push_back(char((~len >> 8) & 0xff));
    z.append(raw, pos, len);
    if (raw.empty()) break;
  }
  std::uint32_t a = 1, b = 0;  // Adler-32
  for (unsigned char ch : raw) a = (a + ch) % 65521u, b = (b + a) % 65521u;
  be32(z, (b << 16) | a);
  std::string header;
  be32(header, std::uint32_t(width));
  be32(header, std::uint32_t(height));
  header += std::string("\x08\x02\x00\x00\x00", 5);  // 8 bit, RGB, deflate, no filter, no interlace
  std::string png = "\x89PNG\r\n\x1a\n";
  chunk(png, "IHDR", header);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", "");
  return png;
}

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t(std::uint8_t(bytes[i])) << 16) |
                            (std::uint32_t(std::uint8_t(bytes[i + 1])) << 8) | std::uint8_t(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out.push_back(table[(v >> s) & 63]);
  }
  if (i < bytes.size()) {
    std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= std::uint32_t(std::uint8_t(bytes[i + 1])) << 8;
    out.push_back(table[(v >> 18) & 63]);
    out.push_back(table[(v >> 12) & 63]);
    out.push_back(i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=');
    out.push_back('=');
  }
  return out;
}
}  // namespace

void SvgDocument::heatmapImage(const std::vector<double>& values, int nx, int ny, double x0, double x1,
                               double y0, double y1) {
  std::vector<unsigned char> rgb(std::size_t(nx) * std::size_t(ny) * 3, 255);
  for (int row = 0; row < ny; ++row) {
    const int j = ny - 1 - row;  // PNG rows run top to bottom, user y upwards
    for (int i = 0; i < nx; ++i) {
      const double v = values[std::size_t(j) * nx + i];
      if (std::isnan(v)) continue;
      const Rgb c = colormap(v);
      unsigned char* p = &rgb[(std::size_t(row) * nx + i) * 3];
      p[0] = c.r, p[1] = c.g, p[2] = c.b;
    }
  }
  const double left = std::min(px(x0), px(x1)), top = std::min(py(y0), py(y1));
  body_ += "<image x=\"" + num(left) + "\" y=\"" + num(top) + "\" width=\"" + num(std::abs(px(x1) - px(x0))) +
           "\" height=\"" + num(std::abs(py(y1) - py(y0))) +
           "\" preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" href=\"data:image/png;base64," +
           base64(pngStored(rgb, nx, ny)) + "\"/>\n";
}

void SvgDocument::axes(const std::string& xlabel, const std::string& ylabel, int xticks, int yticks) {
  rect(xmin_, ymin_, xmax_, ymax_, "none", "#000", 1.0);
  const std::vector<double> xs = niceTicks(std::min(xmin_, xmax_), std::max(xmin_, xmax_), xticks);
  for (const double x : xs) {
    body_ += "<line x1=\"" + num(px(x)) + "\" y1=\"" + num(py(ymin_)) + "\" x2=\"" + num(px(x)) +
             "\" y2=\"" + num(py(ymin_) + 5) + "\" stroke=\"#000\"/>\n";
    textPx(px(x), py(ymin_) + 17, tickLabel(x, tickStep(xs)), 10, "middle");
  }
  const std::vector<double> ys = niceTicks(std::min(ymin_, ymax_), std::max(ymin_, ymax_), yticks);
  for (const double y : ys) {
    body_ += "<line x1=\"" + num(px(xmin_) - 5) + "\" y1=\"" + num(py(y)) + "\" x2=\"" +
             num(px(xmin_)) + "\" y2=\"" + num(py(y)) + "\" stroke=\"#000\"/>\n";
    textPx(px(xmin_) - 7, py(y) + 3, tickLabel(y, tickStep(ys)), 10, "end");
  }
  textPx((px(xmin_) + px(xmax_)) / 2, height_ - 5, xlabel, 12, "middle");
  body_ += "<text transform=\"translate(12," + num((py(ymin_) + py(ymax_)) / 2) +
           ") rotate(-90)\" font-size=\"12\" font-family=\"sans-serif\" text-anchor=\"middle\">" +
           escape(ylabel) + "</text>\n";
}

std::string SvgDocument::str() const {
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(width_) << "\" height=\""
      << num(height_) << "\" viewBox=\"0 0 " << num(width_) << " " << num(height_) << "\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n"
      << body_ << "</svg>\n";
  return out.str();
}

void SvgDocument::save(const std::string& path) const {
  std::ofstream file(path);
  if (!file) throw RunError("cannot write " + path);
  file << str();
  if (!file) throw RunError("failed writing " + path);
}

}  // namespace rcfd
