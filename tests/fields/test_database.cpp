// FieldDatabase: layout, round trip, interrupted writer, foreign (h5py-style) files, frame cache.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <list>
#include <random>
#include <thread>

#include "FieldTestUtil.hpp"
#include "core/Hdf5.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {
void expectFramesEqual(const FieldFrame& a, const FieldFrame& b) {
  ASSERT_EQ(a.alpha_p, b.alpha_p);
  ASSERT_EQ(a.u_p, b.u_p);
  ASSERT_EQ(a.u_g, b.u_g);
}
}  // namespace

TEST(FieldDatabase, RoundTripKeepsEveryValue) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  const std::string path = writeWavyDatabase("roundtrip.h5", g, 6, 0.005);
  auto db = FieldDatabase::open(path);
  EXPECT_EQ(db->frameCount(), 6);
  EXPECT_EQ(db->grid(), g);
  EXPECT_DOUBLE_EQ(db->dtRec(), 0.005);
  EXPECT_EQ(db->sceneJson(), "{\"name\":\"test\"}");
  EXPECT_EQ(db->fluidFraction(), variedFluid(g));
  for (int n = 0; n < 6; ++n) {
    FieldFrame expected = makeFrame(g);
    wavyFrame(g, n, expected);
    expectFramesEqual(*db->frame(n), expected);
  }
  EXPECT_EQ(db->cacheStats().misses, 0);
  EXPECT_EQ(db->cacheStats().residentBytes, 6 * db->frameBytes());
  EXPECT_THROW(db->frame(6), std::out_of_range);
}

TEST(FieldDatabase, FileFollowsTheContractLayout) {
  const CartesianGrid g = smallGrid(5, 3, 2);
  const std::string path = writeWavyDatabase("layout.h5", g, 3);
  h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  ASSERT_TRUE(f.valid());
  EXPECT_EQ(h5::readStringAttribute(f, "format").value(), "rcfd-field-database");
  EXPECT_EQ(h5::readNumericAttribute(f, "version").value(), std::vector<double>{1});
  h5::Handle grid(H5Oopen(f, "/grid", H5P_DEFAULT));
  EXPECT_EQ(h5::readNumericAttribute(grid, "shape").value(), (std::vector<double>{5, 3, 2}));
  struct Expect {
    const char* name;
    std::vector<hsize_t> dims;
  };
  for (const Expect& e : {Expect{"/grid/fluid_fraction", {2, 3, 5}}, Expect{"/frames/alpha_p", {3, 2, 3, 5}},
                          Expect{"/frames/u_p", {3, 2, 3, 5, 3}}, Expect{"/frames/u_g", {3, 2, 3, 5, 3}}}) {
    h5::Handle d(H5Dopen2(f, e.name, H5P_DEFAULT));
    ASSERT_TRUE(d.valid()) << e.name;
    EXPECT_EQ(h5::datasetDims(d), e.dims) << e.name;
    h5::Handle type(H5Dget_type(d));
    EXPECT_TRUE(H5Tequal(type, H5T_IEEE_F32LE) > 0) << e.name << " is not float32";
    if (std::string(e.name).rfind("/frames/", 0) == 0) {
      h5::Handle plist(H5Dget_create_plist(d));
      ASSERT_EQ(H5Pget_layout(plist), H5D_CHUNKED) << e.name;
      std::vector<hsize_t> chunk(e.dims.size());
      H5Pget_chunk(plist, int(chunk.size()), chunk.data());
      std::vector<hsize_t> oneFrame = e.dims;
      oneFrame[0] = 1;
      EXPECT_EQ(chunk, oneFrame) << e.name << ": one frame per chunk";
    }
  }
}

// A writer killed after k frames (the child process _exit()s without closing) leaves k readable frames.
TEST(FieldDatabase, InterruptedWriterLeavesTheFramesWritten) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  for (int k : {3, 5}) {
    const std::string path = tempPath("interrupted.h5");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      FieldDatabaseWriter* writer = new FieldDatabaseWriter(path, g, variedFluid(g), 0.01, "{}");
      for (int n = 0; n < k; ++n) {
        FieldFrame f = makeFrame(g);
        wavyFrame(g, n, f);
        writer->append(f);
      }
      _exit(0);  // no close, no destructor: as if the process died
    }
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    auto db = FieldDatabase::open(path);
    ASSERT_EQ(db->frameCount(), k);
    for (int n = 0; n < k; ++n) {
      FieldFrame expected = makeFrame(g);
      wavyFrame(g, n, expected);
      expectFramesEqual(*db->frame(n), expected);
    }
  }
}

// A writer interrupted inside a frame may have extended some datasets: readers trust the frame count
// written after each frame, and without one the shortest dataset.
TEST(FieldDatabase, PartiallyWrittenFrameIsIgnored) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  const std::string path = writeWavyDatabase("partial.h5", g, 4);
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
    for (const char* name : {"/frames/alpha_p", "/frames/u_p"}) {
      h5::Handle d(H5Dopen2(f, name, H5P_DEFAULT));
      auto dims = h5::datasetDims(d);
      dims[0] = 5;
      ASSERT_GE(H5Dset_extent(d, dims.data()), 0);
    }
  }
  EXPECT_EQ(FieldDatabase::open(path)->frameCount(), 4);  // frame_count = 4
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
    ASSERT_GE(H5Adelete_by_name(f, "/frames", "frame_count", H5P_DEFAULT), 0);
  }
  EXPECT_EQ(FieldDatabase::open(path)->frameCount(), 4);  // u_g has 4 frames
}

TEST(FieldDatabase, AbandonedWriterObjectInProcessIsReadable) {
  const CartesianGrid g = smallGrid(3, 3, 3);
  const std::string path = tempPath("abandoned.h5");
  auto writer = std::make_unique<FieldDatabaseWriter>(path, g, variedFluid(g), 0.01, "{}");
  for (int n = 0; n < 4; ++n) {
    FieldFrame f = makeFrame(g);
    wavyFrame(g, n, f);
    writer->append(f);
  }
  // Still open for writing in this process: a separate reader process sees the flushed frames.
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    int code = 1;
    try {
      code = FieldDatabase::open(path)->frameCount() == 4 ? 0 : 1;
    } catch (...) {
      code = 2;
    }
    _exit(code);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  writer->close();
  EXPECT_EQ(FieldDatabase::open(path)->frameCount(), 4);
}

TEST(FieldDatabase, WriterRefusesBadFrames) {
  const CartesianGrid g = smallGrid();
  FieldDatabaseWriter writer(tempPath("refuse.h5"), g, variedFluid(g), 0.01, "{}");
  FieldFrame f = makeFrame(g);
  f.u_g.pop_back();
  EXPECT_NE(expectInputError([&] { writer.append(f); }, "/frames/u_g").find("frame 0"), std::string::npos);
  f = makeFrame(g);
  f.alpha_p[5] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(expectInputError([&] { writer.append(f); }, "/frames/alpha_p").find("NaN"), std::string::npos);
  EXPECT_EQ(writer.framesWritten(), 0);
  std::vector<float> fluid = variedFluid(g);
  fluid[2] = 1.5f;
  EXPECT_NE(expectInputError([&] { FieldDatabaseWriter(tempPath("x.h5"), g, fluid, 0.01, "{}"); },
                             "/grid/fluid_fraction")
                .find("[0, 1]"),
            std::string::npos);
  EXPECT_NE(expectInputError([&] { FieldDatabaseWriter(tempPath("x.h5"), g, variedFluid(g), 0.0, "{}"); },
                             "/@dt_rec"),
            "NO EXCEPTION");
}

// A file from another program: contiguous datasets, variable-length strings, int64 shape, float64
// alpha_p (converted to float32 on read), no frame_count attribute.
TEST(FieldDatabase, LoadsAFileWrittenByAnotherProgram) {
  RawSpec spec;
  const std::string path = tempPath("h5py.h5");
  writeRawDatabase(path, spec);
  for (std::int64_t cache : {std::int64_t(0), std::int64_t(1) << 20}) {
    auto db = FieldDatabase::open(path, FrameStorage{cache});
    ASSERT_EQ(db->frameCount(), spec.frames);
    EXPECT_EQ(db->grid().shape, (std::array<int, 3>{3, 2, 2}));
    EXPECT_EQ(db->sceneJson(), "{\"name\": \"from h5py\"}");
    EXPECT_DOUBLE_EQ(db->dtRec(), 0.01);
    for (int n = 0; n < spec.frames; ++n) {
      const auto f = db->frame(n);
      for (int c = 0; c < 12; ++c) {
        ASSERT_EQ(f->alpha_p[std::size_t(c)], rawValue(n, c, 0));
        for (int d = 0; d < 3; ++d) {
          // Where alpha_P is 0 the reader completes u_P (test_velocity_completion.cpp).
          if (f->alpha_p[std::size_t(c)] > 0.0f) ASSERT_EQ(f->u_p[std::size_t(3 * c + d)], rawValue(n, c, d + 1));
          ASSERT_EQ(f->u_g[std::size_t(3 * c + d)], -rawValue(n, c, d + 1));
        }
      }
    }
  }
}

TEST(FieldDatabase, RefusesBrokenDatabasesNamingTheDataset) {
  struct Case {
    const char* what;
    std::function<void(RawSpec&)> breakIt;
    const char* pointer;
  };
  const std::vector<Case> cases{
      {"missing u_g", [](RawSpec& s) { s.omit = "/frames/u_g"; }, "/frames/u_g"},
      {"missing scene", [](RawSpec& s) { s.omit = "/scene"; }, "/scene"},
      {"missing grid", [](RawSpec& s) { s.omit = "/grid"; }, "/grid"},
      {"missing fluid", [](RawSpec& s) { s.omit = "/grid/fluid_fraction"; }, "/grid/fluid_fraction"},
      {"alpha_p shape", [](RawSpec& s) { s.alphaExtraX = 1; }, "/frames/alpha_p"},
      {"two frames", [](RawSpec& s) { s.frames = 2; }, "/frames"},
      {"negative spacing", [](RawSpec& s) { s.spacing = {0.01, -0.01, 0.01}; }, "/grid@spacing"},
      {"NaN spacing", [](RawSpec& s) { s.spacing = {0.01, std::nan(""), 0.01}; }, "/grid@spacing"},
      {"two spacings", [](RawSpec& s) { s.spacing = {0.01, 0.01}; }, "/grid@spacing"},
      {"fractional shape", [](RawSpec& s) { s.shapeAttr = {3.5, 2, 2}; s.shapeAsDouble = true; }, "/grid@shape"},
      {"zero shape", [](RawSpec& s) { s.shapeAttr = {0, 2, 2}; }, "/grid@shape"},
      {"fluid above 1", [](RawSpec& s) { s.fluidValue = 1.25f; }, "/grid/fluid_fraction"},
      {"NaN in a frame", [](RawSpec& s) { s.nanFrame = 2; }, "/frames/u_p"},
      {"zero dt_rec", [](RawSpec& s) { s.dtRec = 0.0; }, "/@dt_rec"},
      {"wrong format", [](RawSpec& s) { s.format = "something-else"; }, "/@format"},
  };
  for (const auto& c : cases) {
    RawSpec spec;
    c.breakIt(spec);
    const std::string path = tempPath("bad.h5");
    writeRawDatabase(path, spec);
    const std::string message = expectInputError([&] { FieldDatabase::open(path); }, c.pointer);
    EXPECT_NE(message.find(c.pointer), std::string::npos) << c.what << ": " << message;
  }
  EXPECT_NE(expectInputError([] { FieldDatabase::open("/nonexistent/db.h5"); }, ""), "NO EXCEPTION");
}

TEST(FieldDatabase, CachedModeRefusesNaNWhenTheFrameIsRead) {
  RawSpec spec;
  spec.nanFrame = 2;
  const std::string path = tempPath("nan-cached.h5");
  writeRawDatabase(path, spec);
  auto db = FieldDatabase::open(path, FrameStorage{std::int64_t(1) << 20});  // opens: frames not read yet
  EXPECT_NO_THROW(db->frame(1));
  const std::string message = expectInputError([&] { db->frame(2); }, "/frames/u_p");
  EXPECT_NE(message.find("frame 2"), std::string::npos) << message;
}

TEST(FieldDatabase, CacheServesTheSameFramesAsRam) {
  const CartesianGrid g = smallGrid(5, 4, 3);
  const std::string path = writeWavyDatabase("cache.h5", g, 12);
  auto ram = FieldDatabase::open(path);
  auto cached = FieldDatabase::open(path, FrameStorage{3 * ram->frameBytes()});
  std::mt19937_64 rng(7);
  for (int k = 0; k < 60; ++k) {
    const int n = int(rng() % 12);
    expectFramesEqual(*cached->frame(n), *ram->frame(n));
  }
  const auto stats = cached->cacheStats();
  EXPECT_EQ(stats.hits + stats.misses, 60);
  EXPECT_LE(stats.residentBytes, 3 * ram->frameBytes());
}

// Misses equal those of a reference LRU model for a fixed access pattern.
TEST(FieldDatabase, CacheMissesFollowLru) {
  const CartesianGrid g = smallGrid(3, 3, 2);
  const std::string path = writeWavyDatabase("lru.h5", g, 8);
  const std::int64_t frameBytes = g.cellCount() * 7 * 4;
  // Capacity 2 frames: 0 m, 1 m, 0 h, 2 m (evicts 1), 1 m (evicts 0), 0 m (evicts 2), 0 h, 1 h.
  {
    auto db = FieldDatabase::open(path, FrameStorage{2 * frameBytes + frameBytes / 2});
    for (int n : {0, 1, 0, 2, 1, 0, 0, 1}) db->frame(n);
    EXPECT_EQ(db->cacheStats().misses, 5);
    EXPECT_EQ(db->cacheStats().hits, 3);
    EXPECT_EQ(db->cacheStats().residentBytes, 2 * frameBytes);
  }
  // A longer pseudo-random pattern against a reference model, capacity 3 frames.
  std::mt19937_64 rng(11);
  std::vector<int> pattern;
  for (int k = 0; k < 200; ++k) pattern.push_back(int(rng() % 6));
  std::list<int> model;
  std::int64_t expectedMisses = 0;
  for (int n : pattern) {
    auto it = std::find(model.begin(), model.end(), n);
    if (it != model.end()) model.erase(it);
    else {
      ++expectedMisses;
      if (model.size() == 3) model.pop_back();
    }
    model.push_front(n);
  }
  auto db = FieldDatabase::open(path, FrameStorage{3 * frameBytes});
  for (int n : pattern) db->frame(n);
  EXPECT_EQ(db->cacheStats().misses, expectedMisses);
  EXPECT_EQ(db->cacheStats().hits, 200 - expectedMisses);
}

TEST(FieldDatabase, CacheIsThreadSafe) {
  const CartesianGrid g = smallGrid(6, 5, 4);
  const std::string path = writeWavyDatabase("threads.h5", g, 10);
  auto ram = FieldDatabase::open(path);
  auto cached = FieldDatabase::open(path, FrameStorage{4 * ram->frameBytes()});
  std::atomic<int> mismatches{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      std::mt19937_64 rng(100 + t);
      for (int k = 0; k < 100; ++k) {
        const int n = int(rng() % 10);
        const auto a = cached->frame(n), b = ram->frame(n);
        if (a->alpha_p != b->alpha_p || a->u_p != b->u_p || a->u_g != b->u_g) ++mismatches;
      }
    });
  }
  for (auto& th : threads) th.join();
  EXPECT_EQ(mismatches.load(), 0);
  const auto s = cached->cacheStats();
  EXPECT_EQ(s.hits + s.misses, 400);
  EXPECT_LE(s.residentBytes, 4 * ram->frameBytes());
}

TEST(FieldDatabase, CacheSmallerThanAFrameIsRefused) {
  const CartesianGrid g = smallGrid();
  const std::string path = writeWavyDatabase("tiny-cache.h5", g, 3);
  EXPECT_NE(expectInputError([&] { FieldDatabase::open(path, FrameStorage{10}); }, "/rcfd/frame_cache_bytes"),
            "NO EXCEPTION");
  EXPECT_NE(expectInputError([&] { FieldDatabase::open(path, FrameStorage{-1}); }, "/rcfd/frame_cache_bytes"),
            "NO EXCEPTION");
}

TEST(FieldDatabase, InMemoryDatabaseIsValidatedLikeAFile) {
  const CartesianGrid g = smallGrid();
  auto db = makeAnalyticDatabase(g, variedFluid(g), 0.01, 4, [&](int n, double, FieldFrame& f) { wavyFrame(g, n, f); });
  EXPECT_EQ(db->frameCount(), 4);
  FieldFrame expected = makeFrame(g);
  wavyFrame(g, 3, expected);
  expectFramesEqual(*db->frame(3), expected);
  EXPECT_NE(expectInputError([&] { makeAnalyticDatabase(g, variedFluid(g), 0.01, 2, [](int, double, FieldFrame&) {}); },
                             "/frames"),
            "NO EXCEPTION");
  EXPECT_NE(expectInputError(
                [&] {
                  makeAnalyticDatabase(g, variedFluid(g), 0.01, 3, [](int n, double, FieldFrame& f) {
                    if (n == 1) f.u_g[4] = INFINITY;
                  });
                },
                "/frames/u_g"),
            "NO EXCEPTION");
}

TEST(FieldDatabase, CompressedDatabaseReadsBackEqual) {
  const CartesianGrid g = smallGrid(8, 6, 4);
  const std::string plain = writeWavyDatabase("plain.h5", g, 5);
  const std::string packed = tempPath("packed.h5");
  writeAnalyticDatabase(packed, g, variedFluid(g), 0.005, 5, [&](int n, double, FieldFrame& f) { wavyFrame(g, n, f); },
                        "{}", FieldDatabaseWriterOptions{4, true});
  auto a = FieldDatabase::open(plain), b = FieldDatabase::open(packed);
  for (int n = 0; n < 5; ++n) expectFramesEqual(*a->frame(n), *b->frame(n));
}

namespace {
/// A wavy frame with a velocity spread: shares in [0, 1], variances >= 0, all varying by cell and frame.
void spreadFrame(const CartesianGrid& g, int n, FieldFrame& f) {
  wavyFrame(g, n, f);
  const std::size_t cells = std::size_t(g.cellCount());
  f.up_fraction.resize(cells);
  f.u_p_up.resize(3 * cells), f.u_p_down.resize(3 * cells), f.u_p_variance.resize(3 * cells);
  for (std::size_t c = 0; c < cells; ++c) {
    f.up_fraction[c] = float(0.5 + 0.4 * std::sin(double(c) + n));
    for (std::size_t d = 0; d < 3; ++d) {
      f.u_p_up[3 * c + d] = float(1.0 + 0.1 * double(c + d) + n);
      f.u_p_down[3 * c + d] = float(-1.0 - 0.05 * double(c) - n);
      f.u_p_variance[3 * c + d] = float(0.01 * double(c + d + std::size_t(n)));
    }
  }
}
}  // namespace

TEST(FieldDatabase, TheVelocitySpreadIsReadOnlyWhenAskedFor) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  const std::string path = tempPath("spread.h5");
  FieldDatabaseWriterOptions options;
  options.velocitySpread = true;
  writeAnalyticDatabase(path, g, variedFluid(g), 0.005, 5, [&](int n, double, FieldFrame& f) { spreadFrame(g, n, f); },
                        "{}", options);
  for (const std::int64_t cache : {std::int64_t(0), std::int64_t(1) << 20}) {
    auto with = FieldDatabase::open(path, FrameStorage{cache, true});
    auto without = FieldDatabase::open(path, FrameStorage{cache, false});
    EXPECT_TRUE(with->hasVelocitySpread());
    EXPECT_FALSE(without->hasVelocitySpread());
    EXPECT_EQ(with->frameBytes(), g.cellCount() * 17 * 4);
    EXPECT_EQ(without->frameBytes(), g.cellCount() * 7 * 4);
    for (int n = 0; n < 5; ++n) {
      FieldFrame expected = makeFrame(g);
      spreadFrame(g, n, expected);
      const auto a = with->frame(n);
      expectFramesEqual(*a, expected);
      EXPECT_EQ(a->up_fraction, expected.up_fraction);
      EXPECT_EQ(a->u_p_up, expected.u_p_up);
      EXPECT_EQ(a->u_p_down, expected.u_p_down);
      EXPECT_EQ(a->u_p_variance, expected.u_p_variance);
      EXPECT_FALSE(without->frame(n)->hasVelocitySpread());
    }
  }
  // A database without it, asked for it: the missing dataset is named.
  const std::string plain = writeWavyDatabase("nospread.h5", g, 3);
  try {
    FieldDatabase::open(plain, FrameStorage{0, true});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations().size(), 4u);
    EXPECT_EQ(e.violations()[0].pointer, "/frames/up_fraction");
  }
  // Asked for it only if present: opened without it; a file that has it is read with it.
  EXPECT_FALSE(FieldDatabase::open(plain, FrameStorage{0, true, true})->hasVelocitySpread());
  EXPECT_TRUE(FieldDatabase::open(path, FrameStorage{0, true, true})->hasVelocitySpread());
  // Reopened for appending, the writer goes on with the spread and keeps the frames' datasets aligned.
  {
    auto w = FieldDatabaseWriter::reopen(path, g, 3);
    EXPECT_TRUE(w->writesVelocitySpread());
    FieldFrame f = makeFrame(g);
    spreadFrame(g, 9, f);
    w->append(f);
    FieldFrame bare = makeFrame(g);
    wavyFrame(g, 9, bare);
    EXPECT_THROW(w->append(bare), InputError);  // a frame without the spread in a database with it
    w->close();
  }
  auto db = FieldDatabase::open(path, FrameStorage{0, true});
  ASSERT_EQ(db->frameCount(), 4);
  FieldFrame expected = makeFrame(g);
  spreadFrame(g, 9, expected);
  EXPECT_EQ(db->frame(3)->u_p_down, expected.u_p_down);
}

TEST(FieldDatabase, AVelocitySpreadOutOfRangeIsRefusedNamingTheDataset) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  std::vector<FieldFrame> frames;
  for (int n = 0; n < 3; ++n) {
    frames.push_back(makeFrame(g));
    spreadFrame(g, n, frames.back());
  }
  frames[1].up_fraction[5] = 1.5f;
  frames[2].u_p_variance[4] = -0.1f;
  try {
    makeInMemoryDatabase(g, variedFluid(g), 0.005, frames);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations()[0].pointer, "/frames/up_fraction");
    EXPECT_NE(std::string(e.what()).find("[0, 1]"), std::string::npos) << e.what();
  }
  frames[1].up_fraction[5] = 0.5f;
  EXPECT_THROW(makeInMemoryDatabase(g, variedFluid(g), 0.005, frames), InputError);
  frames[2].u_p_variance[4] = 0.1f;
  frames[2].u_p_up.clear();  // part of the spread missing
  EXPECT_THROW(makeInMemoryDatabase(g, variedFluid(g), 0.005, frames), InputError);
}

TEST(FieldDatabase, AStopRequestEndsReadingIntoRamBetweenFrames) {
  // All frames into RAM takes minutes for a long database: a cancelled job is asked before each.
  const CartesianGrid g = smallGrid(4, 3, 2);
  const std::string path = writeWavyDatabase("stopped-read.h5", g, 6, 0.005);
  FrameStorage storage;
  int polls = 0;
  storage.stopRequested = [&] { return ++polls > 3; };
  EXPECT_THROW(FieldDatabase::open(path, storage), Cancelled);
  EXPECT_EQ(polls, 4);  // frames 0-2 read, stopped before frame 3
  storage.stopRequested = [] { return false; };
  EXPECT_EQ(FieldDatabase::open(path, storage)->frameCount(), 6);
}
