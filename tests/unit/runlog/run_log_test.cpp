#include "marsala/runlog/run_log.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/runlog/crc32c.hpp"

namespace marsala::runlog {
namespace {

namespace fs = std::filesystem;

// Check values of CRC-32C (RFC 3720, B.4; the "123456789" check value of the Castagnoli catalogue).
TEST(Crc32c, KnownVectors) {
  const std::string digits = "123456789";
  EXPECT_EQ(crc32c(digits.data(), digits.size()), 0xE3069283u);
  const std::vector<unsigned char> zeros(32, 0x00), ones(32, 0xFF);
  EXPECT_EQ(crc32c(zeros.data(), zeros.size()), 0x8A9136AAu);
  EXPECT_EQ(crc32c(ones.data(), ones.size()), 0x62A8AB43u);
  std::vector<unsigned char> ascending(32);
  for (int i = 0; i < 32; ++i) ascending[i] = static_cast<unsigned char>(i);
  EXPECT_EQ(crc32c(ascending.data(), ascending.size()), 0x46DD794Eu);
  // Continuing from a partial CRC gives the CRC of the whole.
  EXPECT_EQ(crc32c(digits.data() + 4, 5, crc32c(digits.data(), 4)), 0xE3069283u);
}

// Check values of the ISO-HDLC CRC-32 (MCAP's): the catalogue's "123456789", and zlib.crc32 of 32 zeros and ones.
TEST(Crc32Iso, KnownVectors) {
  const std::string digits = "123456789";
  EXPECT_EQ(crc32_iso(digits.data(), digits.size()), 0xCBF43926u);
  const std::vector<unsigned char> zeros(32, 0x00), ones(32, 0xFF);
  EXPECT_EQ(crc32_iso(zeros.data(), zeros.size()), 0x190A55ADu);
  EXPECT_EQ(crc32_iso(ones.data(), ones.size()), 0xFF6CAB0Bu);
  EXPECT_EQ(crc32_iso(digits.data() + 4, 5, crc32_iso(digits.data(), 4)), 0xCBF43926u);
}

class RunLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("marsala_run_log_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = (dir_ / "run.log").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  static proto::LogHeader header() {
    proto::LogHeader h;
    h.set_scenario("ramp");
    h.set_run_id("ramp-d7");
    h.set_agents(3);
    h.set_rows(4);
    h.set_cols(5);
    return h;
  }
  static proto::LogRecord step(std::uint64_t k, int requests) {
    proto::LogRecord r;
    r.mutable_step()->set_step(k);
    for (int i = 0; i < requests; ++i) {
      proto::LoggedRequest* q = r.mutable_step()->add_requests();
      q->set_channel_id(static_cast<std::uint32_t>(i + 1));
      q->set_agent_id(static_cast<std::uint32_t>(i + 1));
      q->set_step(k);
      q->set_accepted(true);
      proto::LoggedDeposition* d = q->add_depositions();
      d->set_row(i);
      d->set_col(2);
      d->set_height_m(0.125 * static_cast<double>(k));
    }
    return r;
  }
  /// Writes a header and steps 0..n-1; returns the offset after each record (the header's first).
  std::vector<std::uint64_t> write_steps(int n) {
    std::vector<std::uint64_t> ends;
    RunLogWriter w = RunLogWriter::create(path_, header());
    ends.push_back(w.bytes());
    for (int k = 0; k < n; ++k) {
      w.append(step(static_cast<std::uint64_t>(k), k % 3));
      ends.push_back(w.bytes());
    }
    return ends;
  }
  std::vector<std::uint64_t> read_steps(RunLogReader& reader) {
    std::vector<std::uint64_t> steps;
    proto::LogRecord r;
    while (reader.next(r)) steps.push_back(r.step().step());
    return steps;
  }

  fs::path dir_;
  std::string path_;
};

TEST_F(RunLogTest, RoundTripsHeaderAndRecordsInOrder) {
  const std::vector<std::uint64_t> ends = write_steps(5);
  EXPECT_EQ(fs::file_size(path_), ends.back());
  RunLogReader reader(path_);
  EXPECT_EQ(reader.header().run_id(), "ramp-d7");
  EXPECT_EQ(reader.header().format_version(), kFormatVersion);
  EXPECT_EQ(reader.first_record_offset(), ends.front());
  proto::LogRecord r;
  for (std::uint64_t k = 0; k < 5; ++k) {
    ASSERT_TRUE(reader.next(r)) << reader.tail_problem();
    EXPECT_TRUE(r.SerializeAsString() == step(k, static_cast<int>(k % 3)).SerializeAsString()) << k;
    EXPECT_EQ(reader.offset(), ends[k + 1]);
  }
  EXPECT_FALSE(reader.next(r));
  EXPECT_EQ(reader.tail_problem(), "");
  EXPECT_EQ(reader.damaged_bytes(), 0u);
}

// A crash can cut the file anywhere: at every possible length, the reader returns exactly the whole records before
// the cut and names the torn one; none is ever half-applied.
TEST_F(RunLogTest, EveryTruncationYieldsTheWholeRecordsBeforeIt) {
  const std::vector<std::uint64_t> ends = write_steps(4);
  std::string full;
  {
    std::ifstream in(path_, std::ios::binary);
    full.assign(std::istreambuf_iterator<char>(in), {});
  }
  for (std::uint64_t cut = ends.front(); cut < full.size(); ++cut) {
    {
      std::ofstream out(path_, std::ios::binary | std::ios::trunc);
      out.write(full.data(), static_cast<std::streamsize>(cut));
    }
    RunLogReader reader(path_);
    const std::vector<std::uint64_t> steps = read_steps(reader);
    std::size_t whole = 0;
    while (whole + 1 < ends.size() && ends[whole + 1] <= cut) ++whole;
    ASSERT_EQ(steps.size(), whole) << "cut at " << cut;
    EXPECT_EQ(reader.offset(), ends[whole]);
    if (cut == ends[whole]) {
      EXPECT_EQ(reader.tail_problem(), "") << cut;
    } else {
      EXPECT_NE(reader.tail_problem().find("truncated record at byte " + std::to_string(ends[whole])),
                std::string::npos)
          << reader.tail_problem();
      EXPECT_EQ(reader.damaged_bytes(), cut - ends[whole]);
    }
  }
}

TEST_F(RunLogTest, AFlippedByteStopsReadingAtItsRecord) {
  const std::vector<std::uint64_t> ends = write_steps(4);
  {
    std::fstream f(path_, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(static_cast<std::streamoff>(ends[2] + kFrameBytes + 3));  // inside step 2's payload
    char c = 0;
    f.seekg(f.tellp());
    f.read(&c, 1);
    c = static_cast<char>(c ^ 0x10);
    f.seekp(static_cast<std::streamoff>(ends[2] + kFrameBytes + 3));
    f.write(&c, 1);
  }
  RunLogReader reader(path_);
  EXPECT_EQ(read_steps(reader), (std::vector<std::uint64_t>{0, 1}));
  EXPECT_NE(reader.tail_problem().find("damaged record at byte " + std::to_string(ends[2]) + ": checksum mismatch"),
            std::string::npos)
      << reader.tail_problem();
}

TEST_F(RunLogTest, AnImplausibleLengthIsDamageNotAnAllocation) {
  const std::vector<std::uint64_t> ends = write_steps(2);
  {
    std::fstream f(path_, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(static_cast<std::streamoff>(ends[1]));
    const char huge[4] = {'\xff', '\xff', '\xff', '\x7f'};
    f.write(huge, 4);
  }
  RunLogReader reader(path_);
  EXPECT_EQ(read_steps(reader), (std::vector<std::uint64_t>{0}));
  EXPECT_NE(reader.tail_problem().find("exceeds"), std::string::npos) << reader.tail_problem();
}

TEST_F(RunLogTest, ContinuingCutsTheDamagedTailAndAppends) {
  const std::vector<std::uint64_t> ends = write_steps(3);
  {
    std::ofstream out(path_, std::ios::binary | std::ios::app);
    out << "torn";
  }
  std::uint64_t good = 0;
  {
    RunLogReader reader(path_);
    EXPECT_EQ(read_steps(reader).size(), 3u);
    EXPECT_NE(reader.tail_problem(), "");
    good = reader.offset();
  }
  EXPECT_EQ(good, ends.back());
  {
    RunLogWriter w = RunLogWriter::continue_at(path_, good);
    w.append(step(3, 1));
    w.sync();
  }
  RunLogReader reader(path_);
  EXPECT_EQ(read_steps(reader), (std::vector<std::uint64_t>{0, 1, 2, 3}));
  EXPECT_EQ(reader.tail_problem(), "");
}

TEST_F(RunLogTest, SeekContinuesAtARecordBoundary) {
  const std::vector<std::uint64_t> ends = write_steps(5);
  RunLogReader reader(path_);
  reader.seek(ends[3]);
  EXPECT_EQ(read_steps(reader), (std::vector<std::uint64_t>{3, 4}));
  EXPECT_THROW(reader.seek(ends.back() + 1), InvalidArgument);
  EXPECT_THROW(reader.seek(4), InvalidArgument);
}

TEST_F(RunLogTest, RefusesWhatIsNotARunLog) {
  {
    std::ofstream out(path_, std::ios::binary);
    out << "ncols 4\nnrows 4\n";
  }
  EXPECT_THROW(RunLogReader reader(path_), ParseError);
  EXPECT_THROW(RunLogReader reader((dir_ / "missing.log").string()), IoError);
  fs::remove(path_);
  write_steps(0);
  EXPECT_THROW(RunLogWriter::create(path_, header()), IoError);  // never overwrites a log
}

}  // namespace
}  // namespace marsala::runlog
