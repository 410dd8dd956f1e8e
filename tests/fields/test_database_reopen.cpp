// FieldDatabaseWriter::reopen: what a resumed database job does with frames sampled after its last
// checkpoint (cut back, then appended again), and the files it refuses.
#include <gtest/gtest.h>

#include "FieldTestUtil.hpp"
#include "core/Hdf5.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>

using namespace rcfd;
using namespace rcfd::test;

TEST(FieldDatabaseReopen, CutsBackToTheKeptFramesAndAppendsAfterThem) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  const std::string path = writeWavyDatabase("reopen.h5", g, 6);
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
    h5::Handle g(H5Gcreate2(f, "/recurrence", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    h5::writeStringDataset(f, "/recurrence/matrix", "stale");  // any object there: reopen removes it
  }
  {
    auto w = FieldDatabaseWriter::reopen(path, g, 4);
    EXPECT_EQ(w->framesWritten(), 4);
    FieldFrame f = makeFrame(g);
    wavyFrame(g, 40, f);  // different content from the discarded frames 4 and 5
    w->append(f);
    w->close();
  }
  auto db = FieldDatabase::open(path);
  ASSERT_EQ(db->frameCount(), 5);
  for (int n = 0; n < 4; ++n) {
    FieldFrame expected = makeFrame(g);
    wavyFrame(g, n, expected);
    EXPECT_EQ(db->frame(n)->alpha_p, expected.alpha_p) << n;
    EXPECT_EQ(db->frame(n)->u_g, expected.u_g) << n;
  }
  FieldFrame appended = makeFrame(g);
  wavyFrame(g, 40, appended);
  EXPECT_EQ(db->frame(4)->alpha_p, appended.alpha_p);
  EXPECT_EQ(db->frame(4)->u_p, appended.u_p);
  EXPECT_EQ(db->fluidFraction(), variedFluid(g));
  EXPECT_DOUBLE_EQ(db->dtRec(), 0.005);
  h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  EXPECT_FALSE(h5::linkExists(f, "/recurrence/matrix"));
}

TEST(FieldDatabaseReopen, KeepingZeroFramesStartsOver) {
  const CartesianGrid g = smallGrid(3, 2, 2);
  const std::string path = writeWavyDatabase("reopen0.h5", g, 4);
  {
    auto w = FieldDatabaseWriter::reopen(path, g, 0);
    for (int n = 10; n < 13; ++n) {
      FieldFrame f = makeFrame(g);
      wavyFrame(g, n, f);
      w->append(f);
    }
  }
  auto db = FieldDatabase::open(path);
  ASSERT_EQ(db->frameCount(), 3);
  FieldFrame expected = makeFrame(g);
  wavyFrame(g, 10, expected);
  EXPECT_EQ(db->frame(0)->alpha_p, expected.alpha_p);
}

TEST(FieldDatabaseReopen, RefusesMoreFramesThanStoredAndAnotherGrid) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  const std::string path = writeWavyDatabase("reopen-bad.h5", g, 3);
  try {
    FieldDatabaseWriter::reopen(path, g, 4);
    FAIL() << "keeping 4 of 3 frames was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/frames"), std::string::npos) << e.what();
  }
  try {
    FieldDatabaseWriter::reopen(path, smallGrid(5, 3, 2), 2);
    FAIL() << "another grid was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/frames/alpha_p"), std::string::npos) << e.what();
  }
  EXPECT_THROW(FieldDatabaseWriter::reopen(tempPath("missing.h5"), g, 0), InputError);
  // The refused attempts left the file as it was.
  EXPECT_EQ(FieldDatabase::open(path)->frameCount(), 3);
}

// Two jobs on one database: one stores its recurrence matrix (HDF5 holds an exclusive lock on the file
// while it is open for writing) while the other opens the database. The reader waits for the writer
// instead of reporting the file as damaged (this failed the end-to-end test at random before).
TEST(FieldDatabaseReopen, OpeningWaitsWhileAnotherProcessWritesTheFile) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  const std::string path = writeWavyDatabase("locked.h5", g, 3);
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t writer = ::fork();
  ASSERT_GE(writer, 0);
  if (writer == 0) {  // a real second process, as a second solver would be
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const char byte = f >= 0 ? 1 : 0;
    (void)!::write(ready[1], &byte, 1);
    ::usleep(400000);
    if (f >= 0) H5Fclose(f);
    ::_exit(0);
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  ASSERT_EQ(byte, 1) << "the writer could not open the file";
  const auto start = std::chrono::steady_clock::now();
  std::shared_ptr<FieldDatabase> db;
  EXPECT_NO_THROW(db = FieldDatabase::open(path));
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  int status = 0;
  ::waitpid(writer, &status, 0);
  ::close(ready[0]), ::close(ready[1]);
  ASSERT_TRUE(db);
  EXPECT_EQ(db->frameCount(), 3);
  EXPECT_GT(waited, 0.2) << "opened while the writer still held the file: the lock was not tested";
  // A file that is not locked but damaged fails at once, without waiting.
  const std::string junk = tempPath("junk.h5");
  { std::ofstream(junk) << "\x89HDF\r\n\x1a\n" << std::string(64, '\0'); }
  const auto junkStart = std::chrono::steady_clock::now();
  EXPECT_THROW(FieldDatabase::open(junk), InputError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - junkStart).count(), 1.0);
}
