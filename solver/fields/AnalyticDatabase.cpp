#include "fields/AnalyticDatabase.hpp"

namespace rcfd {

FieldFrame makeFrame(const CartesianGrid& grid) {
  const std::size_t cells = std::size_t(grid.cellCount());
  FieldFrame f;
  f.alpha_p.assign(cells, 0.0f);
  f.u_p.assign(3 * cells, 0.0f);
  f.u_g.assign(3 * cells, 0.0f);
  return f;
}

int writeAnalyticDatabase(const std::string& path, const CartesianGrid& grid,
                          const std::vector<float>& fluidFraction, double dtRec, int frames,
                          const FrameFunction& fill, const std::string& sceneJson,
                          FieldDatabaseWriterOptions options) {
  FieldDatabaseWriter writer(path, grid, fluidFraction, dtRec, sceneJson, options);
  for (int n = 0; n < frames; ++n) {
    FieldFrame f = makeFrame(grid);
    fill(n, n * dtRec, f);
    writer.append(f);
  }
  writer.close();
  return writer.framesWritten();
}

std::shared_ptr<FieldDatabase> makeAnalyticDatabase(const CartesianGrid& grid,
                                                    const std::vector<float>& fluidFraction,
                                                    double dtRec, int frames, const FrameFunction& fill,
                                                    const std::string& sceneJson) {
  std::vector<FieldFrame> all;
  all.reserve(std::size_t(std::max(frames, 0)));
  for (int n = 0; n < frames; ++n) {
    all.push_back(makeFrame(grid));
    fill(n, n * dtRec, all.back());
  }
  return makeInMemoryDatabase(grid, fluidFraction, dtRec, std::move(all), sceneJson);
}

}  // namespace rcfd
