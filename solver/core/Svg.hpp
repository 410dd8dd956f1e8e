#pragma once
/// \file Svg.hpp
/// A minimal SVG writer for rcfd's figures (apparatus sections, recurrence plots, histograms, heat maps).
/// Drawing happens in user coordinates (e.g. metres, x right, y up); the document maps them to pixels
/// with y flipped, so callers never think about SVG's downward y axis.

#include <array>
#include <string>
#include <vector>

namespace rcfd {

struct Rgb {
  unsigned char r = 0, g = 0, b = 0;
  std::string hex() const;
};

/// Perceptually ordered colour map (viridis-like) for values in [0, 1]; clamps outside.
Rgb colormap(double value);

class SvgDocument {
 public:
  /// A figure of widthPx x heightPx pixels showing the user-space box [xmin, xmax] x [ymin, ymax],
  /// with `marginPx` pixels around it for axes and labels.
  SvgDocument(double xmin, double xmax, double ymin, double ymax, double widthPx, double heightPx,
              double marginPx = 40.0);

  void line(double x0, double y0, double x1, double y1, const std::string& stroke = "#000",
            double widthPx = 1.0, const std::string& dash = "");
  /// A line with stroke opacity in [0, 1] (translucent rays, e.g. a spray cone).
  void translucentLine(double x0, double y0, double x1, double y1, const std::string& stroke,
                       double widthPx, double opacity, const std::string& dash = "");
  void polyline(const std::vector<std::array<double, 2>>& points, const std::string& stroke = "#000",
                double widthPx = 1.0);
  void polygon(const std::vector<std::array<double, 2>>& points, const std::string& fill,
               const std::string& stroke = "none", double widthPx = 1.0, double opacity = 1.0);
  void rect(double x0, double y0, double x1, double y1, const std::string& fill,
            const std::string& stroke = "none", double widthPx = 0.0, double opacity = 1.0);
  void circle(double x, double y, double radiusPx, const std::string& fill);
  /// Text at a user-space point; anchor "start", "middle" or "end".
  void text(double x, double y, const std::string& text, double sizePx = 12.0,
            const std::string& anchor = "start", const std::string& fill = "#000");
  /// Text at pixel coordinates (titles, captions outside the plot box).
  void textPx(double xPx, double yPx, const std::string& text, double sizePx = 12.0,
              const std::string& anchor = "start");
  /// A nx x ny array (x fastest) of values in [0, 1] drawn as cells over [x0,x1] x [y0,y1];
  /// NaN cells are left blank.
  void heatmap(const std::vector<double>& values, int nx, int ny, double x0, double x1, double y0,
               double y1);
  /// Like heatmap(), for large arrays (e.g. a 400 x 400 recurrence plot): the cells are embedded as
  /// one PNG image (uncompressed, base64), a fraction of the size of one <rect> per cell. NaN: white.
  void heatmapImage(const std::vector<double>& values, int nx, int ny, double x0, double x1, double y0,
                    double y1);
  /// Axis box with ticks and labels along the plot area's edges: at round numbers (niceTicks(), about
  /// `xticks` and `yticks` intervals), labelled with the decimals their step needs.
  void axes(const std::string& xlabel, const std::string& ylabel, int xticks = 5, int yticks = 5);

  std::string str() const;
  /// Writes the document; throws rcfd::RunError if the file cannot be written.
  void save(const std::string& path) const;

  double px(double x) const;  ///< user x -> pixel x
  double py(double y) const;  ///< user y -> pixel y

 private:
  double xmin_, xmax_, ymin_, ymax_, width_, height_, margin_;
  std::string body_;
};

}  // namespace rcfd
