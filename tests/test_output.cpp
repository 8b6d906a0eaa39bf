// sim_host/io/output.hpp: atomic checked writes, safe folder names, output folders
// owned by their command.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/io/csv.hpp"
#include "sim_host/io/output.hpp"

namespace fs = std::filesystem;
using vines::host::AtomicFile;
using vines::host::CsvWriter;
using vines::host::OutputDir;
using vines::host::safe_file_name;
using vines::host::write_file_atomic;

namespace {

// A fresh empty folder per test, removed after it.
class OutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vines_test_output_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::set<std::string> names() const {
    std::set<std::string> s;
    for (const auto& e : fs::directory_iterator(dir_)) s.insert(e.path().filename().string());
    return s;
  }
  fs::path dir_;
};

std::string read(const std::string& path) {
  std::ostringstream s;
  s << std::ifstream(path).rdbuf();
  return s.str();
}

// Files larger than `bytes` cannot be written (EFBIG) while it lives; SIGXFSZ ignored.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    old_signal_ = std::signal(SIGXFSZ, SIG_IGN);
    ::getrlimit(RLIMIT_FSIZE, &old_);
    rlimit lim = old_;
    lim.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &lim);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_signal_);
  }

 private:
  rlimit old_{};
  void (*old_signal_)(int);
};

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// ---- atomic writes ----
TEST_F(OutputTest, AtomicWriteReplacesTheFileWhole) {
  write_file_atomic(path("a.json"), "old\n");
  write_file_atomic(path("a.json"), "new\n");
  EXPECT_EQ(read(path("a.json")), "new\n");
  EXPECT_EQ(names(), std::set<std::string>{"a.json"});  // no temporary file left
}

TEST_F(OutputTest, ReplacedFileKeepsItsModeAndNewFileFollowsTheUmask) {
  const mode_t mask = ::umask(0);
  ::umask(mask);
  write_file_atomic(path("new.json"), "x");
  write_file_atomic(path("old.json"), "x");
  fs::permissions(dir_ / "old.json", fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  write_file_atomic(path("old.json"), "y");
  EXPECT_EQ(fs::status(dir_ / "new.json").permissions(), static_cast<fs::perms>(0666 & ~mask));
  EXPECT_EQ(fs::status(dir_ / "old.json").permissions(), static_cast<fs::perms>(0640));
}

TEST_F(OutputTest, FailedWriteLeavesTheOldFileAndNoTemporaryFile) {
  write_file_atomic(path("a.json"), "old\n");
  std::string msg;
  {
    const FileSizeLimit limit(1024);
    msg = message_of([&] { write_file_atomic(path("a.json"), std::string(1 << 20, 'x')); });
  }
  EXPECT_EQ(msg, path("a.json") + ": cannot write: File too large");
  EXPECT_EQ(read(path("a.json")), "old\n");
  EXPECT_EQ(names(), std::set<std::string>{"a.json"});
}

TEST_F(OutputTest, UncommittedFileIsDroppedAndTheTargetKept) {
  write_file_atomic(path("a.csv"), "old\n");
  {
    CsvWriter csv(path("a.csv"));
    csv.raw("half").end_row();  // an exception before close(): nothing replaced
  }
  EXPECT_EQ(read(path("a.csv")), "old\n");
  EXPECT_EQ(names(), std::set<std::string>{"a.csv"});
  {
    CsvWriter csv(path("a.csv"));
    csv.raw("x").integer(1).end_row();
    csv.close();
  }
  EXPECT_EQ(read(path("a.csv")), "x,1\n");
}

TEST_F(OutputTest, CsvWriterFailsWithThePathAndTheReason) {
  std::string msg;
  {
    const FileSizeLimit limit(1024);
    msg = message_of([&] {
      CsvWriter csv(path("big.csv"));
      for (int i = 0; i < 100000; ++i) csv.integer(i).end_row();
      csv.close();
    });
  }
  EXPECT_EQ(msg, path("big.csv") + ": cannot write: File too large");
  EXPECT_TRUE(names().empty());
}

TEST_F(OutputTest, MissingFolderIsNamedWithTheReason) {
  EXPECT_EQ(message_of([&] { write_file_atomic(path("no/such/a.json"), "x"); }),
            path("no/such/a.json") + ": cannot write: No such file or directory");
}

TEST_F(OutputTest, SymbolicLinkIsRefusedAndItsFileKept) {
  write_file_atomic(path("real.csv"), "old\n");
  fs::create_symlink("real.csv", dir_ / "link.csv");
  EXPECT_EQ(message_of([&] { write_file_atomic(path("link.csv"), "new\n"); }),
            path("link.csv") + ": cannot write: a symbolic link (vines writes no file through a link: remove it or "
                               "give another path)");
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.csv"));
  EXPECT_EQ(read(path("real.csv")), "old\n");
  fs::create_symlink("nowhere.csv", dir_ / "dangling.csv");  // would create a file elsewhere
  EXPECT_NE(message_of([&] { write_file_atomic(path("dangling.csv"), "new\n"); }), "");
  EXPECT_FALSE(fs::exists(dir_ / "nowhere.csv"));
}

TEST(Output, DeviceIsWrittenInPlace) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  write_file_atomic("/dev/null", "x");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_EQ(message_of([] { write_file_atomic("/dev/full", "x"); }),
            "/dev/full: cannot write: No space left on device");
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

// ---- safe names ----
TEST(Output, SafeFileNames) {
  EXPECT_EQ(safe_file_name("elcentro_vines-2.b"), "elcentro_vines-2.b");
  EXPECT_EQ(safe_file_name("../../evil"), "___.._evil");
  EXPECT_EQ(safe_file_name(".."), "__");
  EXPECT_EQ(safe_file_name("."), "_");
  EXPECT_EQ(safe_file_name(""), "_");
  EXPECT_EQ(safe_file_name(".hidden"), "_hidden");
  EXPECT_EQ(safe_file_name("a\nb\tc\x01 d/e\\f"), "a_b_c__d_e_f");
  EXPECT_EQ(safe_file_name("K\xc5\x8d" "be"), "K__be");
  EXPECT_EQ(safe_file_name(std::string(5000, 'a')).size(), 100u);
}

// ---- output folders ----
TEST_F(OutputTest, FolderIsCreated) {
  const OutputDir out(path("new/run"), "vines run", {"summary.json"});
  EXPECT_TRUE(fs::is_directory(dir_ / "new" / "run"));
  EXPECT_EQ(out.file("summary.json"), path("new/run") + "/summary.json");
}

TEST_F(OutputTest, FinishRemovesStaleFilesOfTheCommand) {
  { const OutputDir earlier(dir_.string(), "vines run", {"summary.json", "timeseries.csv"}); }
  write_file_atomic(path("summary.json"), "old");
  write_file_atomic(path("timeseries.csv"), "old");
  write_file_atomic(path(".timeseries.csv.tmp-abc123"), "left by a kill");
  const OutputDir out(dir_.string(), "vines run", {"summary.json", "timeseries.csv"});
  write_file_atomic(out.file("summary.json"), "new");
  out.finish({"summary.json"});
  EXPECT_EQ(names(), (std::set<std::string>{".vines-output", "summary.json"}));
  EXPECT_EQ(read(path("summary.json")), "new");
}

TEST_F(OutputTest, PatternsNameTheCommandsFiles) {
  const std::vector<std::string> owned{"stress.json", "case_*.toml", "case_*_record.txt"};
  { const OutputDir earlier(dir_.string(), "vines stress", owned); }
  write_file_atomic(path("case_7.toml"), "old");
  write_file_atomic(path("case_7_record.txt"), "old");
  const OutputDir out(dir_.string(), "vines stress", owned);
  write_file_atomic(out.file("case_9.toml"), "new");
  out.finish({"case_9.toml"});
  EXPECT_EQ(names(), (std::set<std::string>{".vines-output", "case_9.toml"}));
}

// Ownership by the marker, not by file names: a folder of files named like a
// command's outputs, without the marker vines writes, is not vines'.
TEST_F(OutputTest, FolderWithoutTheMarkerIsRefusedAndLeftAlone) {
  write_file_atomic(path("summary.json"), "someone else's");
  const std::string msg = message_of([&] { OutputDir(dir_.string(), "vines run", {"summary.json"}); });
  EXPECT_EQ(msg, dir_.string() + ": holds files but no .vines-output marker, so no vines made it (summary.json): "
                                 "give an empty or new folder");
  EXPECT_EQ(names(), std::set<std::string>{"summary.json"});
  EXPECT_EQ(read(path("summary.json")), "someone else's");
}

TEST_F(OutputTest, FolderWithForeignFilesOrLinksIsRefusedAndLeftAlone) {
  { const OutputDir earlier(dir_.string(), "vines run", {"summary.json", "timeseries.csv"}); }
  write_file_atomic(path("notes.txt"), "mine");
  fs::create_directories(dir_ / "plots");
  write_file_atomic(path("elsewhere.json"), "someone else's");
  fs::create_symlink("elsewhere.json", dir_ / "summary.json");
  fs::create_hard_link(dir_ / "notes.txt", dir_ / "timeseries.csv");
  const std::string msg =
      message_of([&] { OutputDir(dir_.string(), "vines run", {"summary.json", "timeseries.csv"}); });
  EXPECT_EQ(msg, dir_.string() + ": holds files vines run does not write (elsewhere.json, notes.txt (a hard link), "
                                 "plots/, summary.json (a link), timeseries.csv (a hard link)): give an empty or "
                                 "new folder, or one of vines run's own");
  EXPECT_EQ(read(path("elsewhere.json")), "someone else's");
}

// The folder is locked while its command writes: a second command is refused,
// naming the first; another command's folder is refused; the lock goes with
// the command.
TEST_F(OutputTest, FolderInUseOrOfAnotherCommandIsRefused) {
  {
    const OutputDir first(dir_.string(), "vines sweep", {"results.csv"}, "abc");
    EXPECT_EQ(message_of([&] { OutputDir(dir_.string(), "vines sweep", {"results.csv"}); }),
              dir_.string() + ": in use by vines sweep (process " + std::to_string(::getpid()) +
                  "): wait for it to end, or give another folder");
  }
  const OutputDir again(dir_.string(), "vines sweep", {"results.csv"});
  EXPECT_EQ(message_of([&] { OutputDir(path("."), "vines run", {"summary.json"}); }),
            path(".") + ": in use by vines sweep (process " + std::to_string(::getpid()) +
                "): wait for it to end, or give another folder");
}

TEST_F(OutputTest, AnotherCommandsFolderOrAForgedMarkerIsRefused) {
  { const OutputDir sweep(dir_.string(), "vines sweep", {"results.csv"}); }
  EXPECT_EQ(message_of([&] { OutputDir(dir_.string(), "vines run", {"summary.json"}); }),
            dir_.string() + ": vines sweep's folder, not vines run's: give another folder");
  write_file_atomic(path(".vines-output"), "not json");
  EXPECT_EQ(message_of([&] { OutputDir(dir_.string(), "vines sweep", {"results.csv"}); }),
            dir_.string() + ": .vines-output is not a vines marker: give another folder");
  fs::remove(dir_ / ".vines-output");
  write_file_atomic(path("target"), "{}");
  fs::create_symlink("target", dir_ / ".vines-output");
  EXPECT_EQ(message_of([&] { OutputDir(dir_.string(), "vines sweep", {"results.csv"}); }),
            path(".vines-output") + ": not a file vines wrote (a link or a folder): refusing the folder");
}

TEST_F(OutputTest, EmptyPathAndFileInTheWayAreRefused) {
  EXPECT_EQ(message_of([] { OutputDir("", "vines run", {"summary.json"}); }),
            "vines run: the output folder is an empty path");
  write_file_atomic(path("file"), "x");
  EXPECT_EQ(message_of([&] { OutputDir(path("file"), "vines run", {"summary.json"}); }),
            path("file") + ": cannot create: a file of that name exists");
  const std::string below = message_of([&] { OutputDir(path("file/sub"), "vines run", {"summary.json"}); });
  EXPECT_EQ(below.rfind(path("file/sub") + ": cannot create: ", 0), 0u) << below;
  // A symbolic link to nowhere: said so (it was "File exists"), for a run's
  // folder and a sweep's alike.
  fs::create_symlink("nowhere", dir_ / "gone");
  const std::string said = path("gone") + ": cannot create: a symbolic link to nowhere, which does not exist";
  EXPECT_EQ(message_of([&] { OutputDir(path("gone"), "vines run", {"summary.json"}); }).rfind(said, 0), 0u);
  EXPECT_EQ(message_of([&] { vines::host::create_folder(path("gone")); }).rfind(said, 0), 0u);
}

// CsvWriter's numbers come from std::to_chars for "%.Nf", "%.Ng", "%.Ne": the
// same text as snprintf (the C library's printf), on values that stress
// rounding, exponents, subnormals, signed zeros and non-finite values.
TEST(Csv, NumbersAreWhatPrintfWrites) {
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 0.5, 1.5, 2.5, 9.9999999995, 99999.99995, 1e-5, 1e-4,
                                123456789.0, 1e15, 1e16, 1e17, 1e22, 1e300, -1e-300, 4.9e-324, 2.2250738585072014e-308,
                                0.1, 0.2, 0.3, 1.0 / 3.0, 2.0 / 3.0, 3.14159265358979, -0.0139997764,
                                std::numeric_limits<double>::max(), std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()};
  std::uint64_t x = 0x9E3779B97F4A7C15ull;
  for (int i = 0; i < 20000; ++i) {  // random bit patterns, and random values in the ranges outputs take
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    double v;
    std::memcpy(&v, &x, sizeof v);
    values.push_back(v);
    values.push_back(static_cast<double>(x % 2000001) / 1000.0 - 1000.0);
  }
  for (const char* format : {"%.10g", "%.9g", "%.6g", "%.3g", "%.1g", "%.0g", "%.17g", "%.6f", "%.1f", "%.0f",
                             "%.3e", "%.12e"}) {
    for (double v : values) {
      char want[512], got[512];
      const int n = std::snprintf(want, sizeof want, format, v);
      const int m = vines::host::format_number(got, sizeof got, v, format);
      ASSERT_EQ(std::string(want, static_cast<std::size_t>(n)), std::string(got, static_cast<std::size_t>(m)))
          << format << " of " << v;
    }
  }
}

// A number longer than any short buffer is written whole.
TEST_F(OutputTest, LongNumbersAreWrittenWhole) {
  {
    CsvWriter csv(path("long.csv"));
    csv.number(1e300, "%.2f").number(-1e300, "%12.3f").end_row();
    csv.close();
  }
  char want[1024];
  const int a = std::snprintf(want, sizeof want, "%.2f,", 1e300);
  std::snprintf(want + a, sizeof want - static_cast<std::size_t>(a), "%12.3f\n", -1e300);
  EXPECT_EQ(read(path("long.csv")), std::string(want));
}
