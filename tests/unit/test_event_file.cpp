// TensorBoard event files (learner/run_dir/event_file.hpp, learner/run_dir/csv_events.hpp): records read back with
// their CRCs checked, a flipped byte found, a torn tail tolerated and cut on resume, CSV rows as
// grouped scalars; an independent decoder (Python's protobuf, with the Event schema declared in
// the test) reads the same file; a run killed and resumed has every scalar once, in step order.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "learner/run_dir/csv_events.hpp"
#include "learner/run_dir/event_file.hpp"

namespace masa::learner {
namespace {
namespace fs = std::filesystem;

fs::path freshEventDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("masa_events_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(EventFile, ScalarsAndTextReadBackInOrderWithTheFileVersionFirst) {
  const fs::path d = freshEventDir("roundtrip");
  {
    EventFile f(d.string());
    f.text("config", 0, preformatted("task: a1_beam\nseed: 3"));
    for (int k = 1; k <= 5; ++k) f.scalar("train/return", 100 * k, 0.5 * k, 1.7e9 + k);
  }
  const EventFileContents c = readEventFile((d / EventFile::kFileName).string());
  ASSERT_EQ(c.records.size(), 7u);
  EXPECT_FALSE(c.torn_tail);
  EXPECT_EQ(c.records[0].file_version, "brain.Event:2");
  EXPECT_EQ(c.records[1].tag, "config");
  EXPECT_EQ(c.records[1].text, "    task: a1_beam\n    seed: 3");
  for (int k = 1; k <= 5; ++k) {
    const EventRecord& r = c.records[1 + k];
    EXPECT_EQ(r.tag, "train/return");
    EXPECT_TRUE(r.is_scalar);
    EXPECT_EQ(r.step, 100 * k);
    EXPECT_FLOAT_EQ(r.value, 0.5f * k);
    EXPECT_DOUBLE_EQ(r.wall_time, 1.7e9 + k);
  }
}

TEST(EventFile, AFlippedByteIsFoundByTheCrcAndATornTailIsReadAsSuchAndCutOnResume) {
  const fs::path d = freshEventDir("damage");
  {
    EventFile f(d.string());
    for (int k = 1; k <= 4; ++k) f.scalar("a", k, k);
  }
  const std::string path = (d / EventFile::kFileName).string();
  const auto whole = readEventFile(path);
  // Every byte of the third record, flipped in turn, is refused naming that record's offset.
  const uint64_t from = whole.ends[1], to = whole.ends[2];
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  for (uint64_t at = from; at < to; ++at) {
    std::string damaged = bytes;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x10);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << damaged;
    try {
      readEventFile(path);
      ADD_FAILURE() << "a flipped byte at " << at << " was read";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("byte " + std::to_string(from)), std::string::npos) << e.what();
    }
  }
  // A run killed in the middle of a record: the records before it are read, the tail is torn.
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes.substr(0, whole.ends[3] - 5);
  const auto torn = readEventFile(path);
  EXPECT_TRUE(torn.torn_tail);
  EXPECT_EQ(torn.records.size(), 3u);  // the version and steps 1-2; step 3's record is cut short
  truncateEventFile(path, 2);
  const auto cut = readEventFile(path);
  EXPECT_FALSE(cut.torn_tail);
  ASSERT_EQ(cut.records.size(), 3u);
  EXPECT_EQ(cut.records.back().step, 2);
}

TEST(CsvEvents, RowsBecomeGroupedScalarsAtTheirStepAndNanIsLeftOut) {
  EXPECT_EQ(eventTag("learn", "eval_return"), "eval/return");
  EXPECT_EQ(eventTag("learn", "term_keypoints"), "reward_terms/keypoints");
  EXPECT_EQ(eventTag("learn", "fps"), "perf/fps");
  EXPECT_EQ(eventTag("learn", "kl"), "learn/kl");
  EXPECT_EQ(eventTag("off_policy", "q_loss"), "off_policy/q_loss");
  EXPECT_EQ(eventTag("td3", "train_return"), "train/return");
  const fs::path d = freshEventDir("csv");
  const std::string csv = (d / "metrics.csv").string();
  EventFile f(d.string());
  CsvEvents mirror(f, csv, "env_steps", "learn");
  std::ofstream out(csv);
  out << "update,env_steps,return,success,kl,eval_return\n" << "1,512,nan,-1,0.01,nan\n" << std::flush;
  mirror.mirrorLastRow();
  out << "2,1024,12.5,-1,0.02,30\n" << std::flush;
  mirror.mirrorLastRow();
  const auto c = readEventFile(f.path());
  std::map<std::string, std::vector<std::pair<int64_t, float>>> by_tag;
  for (const auto& r : c.records)
    if (r.is_scalar) by_tag[r.tag].push_back({r.step, r.value});
  EXPECT_EQ(by_tag["progress/update"], (std::vector<std::pair<int64_t, float>>{{512, 1.0f}, {1024, 2.0f}}));
  EXPECT_EQ(by_tag["train/return"], (std::vector<std::pair<int64_t, float>>{{1024, 12.5f}}));
  EXPECT_EQ(by_tag["eval/return"], (std::vector<std::pair<int64_t, float>>{{1024, 30.0f}}));
  EXPECT_EQ(by_tag["learn/kl"].size(), 2u);
  EXPECT_EQ(by_tag.count("train/success"), 0u);  // -1: no success measure
}

// Python's protobuf (Debian's python3-protobuf) with the Event, Summary, Value and TensorProto
// fields declared by number: an independent reading of the same bytes.
TEST(EventFile, AnIndependentProtobufDecoderReadsTheSameEvents) {
  // Debian's Python, where python3-protobuf (pulled in by python3-onnx, scripts/install_deps.sh) is.
  if (std::system("/usr/bin/python3 -c 'import google.protobuf' 2> /dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no protobuf (Debian's python3-protobuf)";
  const fs::path d = freshEventDir("python");
  {
    EventFile f(d.string());
    f.text("config", 0, "hello");
    f.scalar("eval/return", 4096, 12.25);
  }
  const std::string cmd = "/usr/bin/python3 " + std::string(MASA_SOURCE_DIR) + "/tests/tools/read_tfevents.py " +
                          (d / EventFile::kFileName).string() + " > " + (d / "read.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << std::ifstream((d / "read.txt").string()).rdbuf();
  std::ifstream in((d / "read.txt").string());
  const std::string got((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(got, "0 version brain.Event:2\n0 text config hello\n4096 scalar eval/return 12.25\n");
}

}  // namespace
}  // namespace masa::learner
