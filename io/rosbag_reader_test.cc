// BagWriter -> BagReader round trips for each compression, and the reader's errors on damaged
// bags: every one an InputError naming the file and a byte offset, never a crash.
#include "io/rosbag_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "core/util/error.h"
#include "io/rosbag_writer.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;

struct Written {
  std::string topic;
  std::int64_t t_ns;
  std::string data;
};

// Two connections, 60 messages of growing sizes; chunks of 2 kB, so several chunks.
std::vector<Written> WriteBag(const fs::path& file, BagCompression compression) {
  BagWriterOptions options;
  options.compression = compression;
  options.chunk_bytes = 2048;
  BagWriter writer(file, options);
  const std::uint32_t a = writer.AddConnection("/cam0/image_raw", RosImageType());
  const std::uint32_t b = writer.AddConnection("/imu0", RosImuType());
  std::vector<Written> written;
  for (int i = 0; i < 60; ++i) {
    const bool on_a = i % 3 == 0;
    Written w{on_a ? "/cam0/image_raw" : "/imu0", 1'000'000'000'000'000'000 + 5'000'000LL * i,
              std::string(static_cast<std::size_t>(10 + 7 * i), static_cast<char>('a' + i % 26))};
    writer.Write(on_a ? a : b, w.t_ns, w.data);
    written.push_back(w);
  }
  writer.Close();
  EXPECT_FALSE(fs::exists(fs::path(file.string() + ".partial")));
  return written;
}

std::vector<Written> ReadAll(const fs::path& file, const std::set<std::uint32_t>& wanted = {}) {
  BagReader reader(file);
  std::vector<Written> read;
  reader.ReadMessages(wanted, [&](const BagMessage& m) {
    read.push_back({m.connection->topic, m.time_ns, std::string(m.data)});
  });
  return read;
}

std::string Bytes(const fs::path& file) { return testing::ReadFileBytes(file); }

void Overwrite(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// The InputError of reading `file` through, or "" when it reads.
std::string ReadError(const fs::path& file) {
  try {
    ReadAll(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

class BagRoundTrip : public ::testing::TestWithParam<BagCompression> {};

TEST_P(BagRoundTrip, EveryMessageComesBackInOrderWithItsTopicTimeAndBytes) {
  const fs::path file = testing::MakeTempDir("bag_round_trip") / "a.bag";
  const std::vector<Written> written = WriteBag(file, GetParam());
  const BagReader reader(file);
  ASSERT_EQ(reader.connections().size(), 2u);
  EXPECT_EQ(reader.connections()[0].type, "sensor_msgs/Image");
  EXPECT_EQ(reader.connections()[0].md5sum, RosImageType().md5sum);
  EXPECT_EQ(reader.connections()[0].message_definition, RosImageType().definition);
  EXPECT_EQ(reader.connections()[0].message_count, 20u);
  EXPECT_EQ(reader.connections()[1].message_count, 40u);
  EXPECT_GT(reader.chunk_infos().size(), 3u);
  EXPECT_EQ(reader.message_count(), 60u);
  const std::vector<Written> read = ReadAll(file);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].topic, written[i].topic) << i;
    EXPECT_EQ(read[i].t_ns, written[i].t_ns) << i;
    EXPECT_EQ(read[i].data, written[i].data) << i;
  }
  // Only the IMU's messages.
  const std::vector<Written> imu = ReadAll(file, {reader.connections()[1].id});
  EXPECT_EQ(imu.size(), 40u);
  for (const Written& w : imu) EXPECT_EQ(w.topic, "/imu0");
}

INSTANTIATE_TEST_SUITE_P(Compressions, BagRoundTrip,
                         ::testing::Values(BagCompression::kNone, BagCompression::kBz2,
                                           BagCompression::kLz4),
                         [](const auto& info) {
                           return std::string(BagCompressionName(info.param));
                         });

TEST(BagReader, TheHeaderRecordIsPaddedTo4096BytesAndTheFileIsOnlyRead) {
  const fs::path file = testing::MakeTempDir("bag_header") / "a.bag";
  WriteBag(file, BagCompression::kNone);
  const std::string before = Bytes(file);
  EXPECT_EQ(before.substr(0, 13), "#ROSBAG V2.0\n");
  // The first chunk follows the 4104-byte header record (4 + header + 4 + padding = 4104).
  EXPECT_EQ(BagReader(file).chunk_infos().front().chunk_pos, 13u + 4104u);
  ReadAll(file);
  EXPECT_EQ(Bytes(file), before);
}

TEST(BagReader, EveryTruncationIsAnErrorNamingFileAndByte) {
  const fs::path dir = testing::MakeTempDir("bag_truncated");
  const fs::path file = dir / "a.bag";
  WriteBag(file, BagCompression::kLz4);
  const std::string bytes = Bytes(file);
  const fs::path cut = dir / "cut.bag";
  for (std::size_t n = 0; n < bytes.size(); n += (n < 4200 ? 97 : 7)) {
    Overwrite(cut, bytes.substr(0, n));
    const std::string error = ReadError(cut);
    ASSERT_THAT(error, HasSubstr(cut.string() + ": byte ")) << "cut at " << n;
    ASSERT_EQ(error.find('\n'), std::string::npos) << "cut at " << n;
  }
  Overwrite(cut, bytes.substr(0, bytes.size() / 2));
  EXPECT_THAT(ReadError(cut), HasSubstr("(truncated)"));
}

TEST(BagReader, DamagedBagsAreOneLineErrors) {
  const fs::path dir = testing::MakeTempDir("bag_damaged");
  const fs::path file = dir / "a.bag";
  WriteBag(file, BagCompression::kNone);
  const std::string bytes = Bytes(file);
  const fs::path bad = dir / "bad.bag";
  const auto with = [&](std::string_view from, std::string_view to) {
    std::string b = bytes;
    const std::size_t at = b.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    b.replace(at, from.size(), to);
    Overwrite(bad, b);
    return ReadError(bad);
  };
  EXPECT_THAT(with("compression=none", "compression=nope"),
              HasSubstr("unknown chunk compression 'nope' (none, bz2, lz4)"));
  EXPECT_THAT(with(std::string("op=\x05", 4), std::string("op=\x2a", 4)),
              HasSubstr("unknown op code 0x2a record where a chunk was expected"));
  EXPECT_THAT(with("#ROSBAG V2.0", "#ROSBAG V1.2"), HasSubstr("bag format 1.2 is not supported"));
  EXPECT_THAT(with("#ROSBAG", "#RUSBAG"), HasSubstr("byte 0: not a ROS bag"));
  EXPECT_THAT(with("index_pos=", "index_pqs="), HasSubstr("no 'index_pos' field"));
  std::string no_index = bytes;
  const std::size_t index_pos = no_index.find("index_pos=") + 10;
  no_index.replace(index_pos, 8, std::string(8, '\0'));
  Overwrite(bad, no_index);
  EXPECT_THAT(ReadError(bad), HasSubstr("rosbag reindex"));
  // Garbage.
  std::mt19937 random(3);
  std::string garbage(5000, '\0');
  for (char& c : garbage) c = static_cast<char>(random());
  Overwrite(bad, garbage);
  EXPECT_THAT(ReadError(bad), HasSubstr("bad.bag: byte 0: not a ROS bag"));
  EXPECT_THAT(ReadError(dir / "none.bag"), HasSubstr("none.bag: file not found"));
  EXPECT_THAT(ReadError(dir), HasSubstr("is a directory"));
}

TEST(BagReader, FlippedBytesReadOrFailCleanly) {
  const fs::path dir = testing::MakeTempDir("bag_flipped");
  const fs::path file = dir / "a.bag";
  for (const BagCompression c : {BagCompression::kNone, BagCompression::kBz2}) {
    WriteBag(file, c);
    const std::string bytes = Bytes(file);
    const fs::path bad = dir / "bad.bag";
    int errors = 0;
    for (std::size_t i = 4100; i < bytes.size(); i += 23) {
      std::string b = bytes;
      b[i] = static_cast<char>(b[i] ^ 0x5a);
      Overwrite(bad, b);
      const std::string error = ReadError(bad);  // an InputError or none; anything else fails
      if (!error.empty()) {
        ++errors;
        EXPECT_THAT(error, MatchesRegex(".*bad\\.bag: (chunk at )?byte [0-9]+.*")) << i;
        EXPECT_EQ(error.find('\n'), std::string::npos) << i;
      }
    }
    EXPECT_GT(errors, 0);
  }
}

TEST(BagReader, ChunkSizesBeyondTheLimitAreRefusedBeforeAllocating) {
  const fs::path file = testing::MakeTempDir("bag_limit") / "a.bag";
  WriteBag(file, BagCompression::kBz2);
  BagReaderOptions options;
  options.max_chunk_bytes = 100;
  BagReader reader(file, options);
  EXPECT_THAT(
      [&] { reader.ReadMessages({}, [](const BagMessage&) {}); },
      ::testing::ThrowsMessage<InputError>(HasSubstr("more than the reader's limit of 100")));
  options.max_chunk_bytes = 0;
  EXPECT_THROW(BagReader(file, options), OptionError);
}

TEST(BagWriter, AbandonedWritersLeaveNoFileAndTimesMustFitARosTime) {
  const fs::path dir = testing::MakeTempDir("bag_writer");
  {
    BagWriter writer(dir / "a.bag");
    const std::uint32_t c = writer.AddConnection("/imu0", RosImuType());
    EXPECT_THROW(writer.Write(c, -1, "x"), OptionError);
    EXPECT_THROW(writer.Write(c, std::int64_t{1} << 62, "x"), OptionError);
  }
  EXPECT_TRUE(fs::is_empty(dir));
  BagWriterOptions options;
  options.chunk_bytes = 0;
  EXPECT_THROW(BagWriter(dir / "b.bag", options), OptionError);
  EXPECT_THROW(BagWriter(dir / "missing" / "c.bag"), OutputError);
}

}  // namespace
}  // namespace pkslam
