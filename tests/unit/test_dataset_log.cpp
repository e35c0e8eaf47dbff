// Offline datasets as LCM logs: what is written is read back exactly, across files; a truncated
// last file and hostile events are reported and change nothing; HDF5 export round-trips; the
// recorder's episodes are the evaluator's.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "common/dataset/dataset_log.hpp"
#include "common/dataset/hdf5_export.hpp"
#include "common/dataset/policy_recorder.hpp"
#include "common/policy/policy_file.hpp"
#include "common/transport/channels.hpp"
#include "tasks/tasks.hpp"

namespace masa::dataset {
namespace {

namespace fs = std::filesystem;

fs::path scratchDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("masa_dataset_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// An episode of random numbers (obs 5, act 3), reproducible from its id.
EpisodeRecord randomEpisode(int64_t id, int length, const std::string& policy, bool terminated) {
  Rng rng(static_cast<uint64_t>(id));
  std::normal_distribution<float> n(0.f, 1.f);
  EpisodeRecord e;
  e.task = "toy";
  e.episode_id = id;
  e.policy_name = policy;
  e.obs = Mat<float>::NullaryExpr(5, length + 1, [&] { return n(rng); });
  e.actions = Mat<float>::NullaryExpr(3, length, [&] { return n(rng); });
  for (int t = 0; t < length; ++t) e.rewards.push_back(n(rng));
  e.terminated = terminated;
  e.truncated = !terminated;
  e.success = terminated ? 0 : 1;
  return e;
}

// The dataset the episodes make, built here column by column (the reader's expected output).
void expectDatasetHolds(const TransitionDataset& d, const std::vector<EpisodeRecord>& eps) {
  ASSERT_EQ(d.episodes.size(), eps.size());
  int64_t col = 0;
  for (size_t k = 0; k < eps.size(); ++k) {
    const EpisodeRecord& e = eps[k];
    const EpisodeInfo& info = d.episodes[k];
    EXPECT_EQ(info.episode_id, e.episode_id);
    EXPECT_EQ(info.start, col);
    ASSERT_EQ(info.length, e.length());
    EXPECT_EQ(d.policy_names.at(static_cast<size_t>(info.policy_id)), e.policy_name);
    EXPECT_EQ(info.success, e.success);
    for (int t = 0; t < e.length(); ++t, ++col) {
      ASSERT_EQ(d.obs.col(col), e.obs.col(t)) << "episode " << k << " step " << t;
      ASSERT_EQ(d.next_obs.col(col), e.obs.col(t + 1)) << "episode " << k << " step " << t;
      ASSERT_EQ(d.actions.col(col), e.actions.col(t));
      ASSERT_EQ(d.rewards(col), e.rewards[static_cast<size_t>(t)]);
      const bool last = t + 1 == e.length();
      ASSERT_EQ(d.terminals[static_cast<size_t>(col)], last && e.terminated);
      ASSERT_EQ(d.timeouts[static_cast<size_t>(col)], last && e.truncated);
    }
  }
  EXPECT_EQ(d.size(), col);
}

// Raw events, for logs a recorder would never write.
void writeRawEvent(lcm::LogFile& log, const std::string& channel, const std::vector<unsigned char>& bytes) {
  lcm::LogEvent ev;
  ev.eventnum = 0;
  ev.timestamp = 1;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(bytes.size());
  ev.data = const_cast<unsigned char*>(bytes.data());
  ASSERT_EQ(log.writeEvent(&ev), 0);
}

std::vector<unsigned char> encode(masa::lcmt_transitions& m) {
  std::vector<unsigned char> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

TEST(DatasetLog, MessagesSplitLongEpisodesAndMarkOnlyTheLast) {
  const EpisodeRecord e = randomEpisode(7, 300, "p", true);
  const auto msgs = episodeMessages(e, 128, 5);
  ASSERT_EQ(msgs.size(), 3u);
  EXPECT_EQ(msgs[0].num_steps, 128);
  EXPECT_EQ(msgs[2].num_steps, 300 - 256);
  EXPECT_EQ(msgs[2].step_offset, 256);
  for (const auto& m : msgs) EXPECT_EQ(checkTransitions(m), "") << "offset " << m.step_offset;
  EXPECT_FALSE(msgs[0].last || msgs[0].terminated || msgs[1].last);
  EXPECT_TRUE(msgs[2].last && msgs[2].terminated && !msgs[2].truncated);
  // A message's last observation is the next one's first: o_128 travels twice.
  EXPECT_EQ(msgs[0].obs[128 * 5], msgs[1].obs[0]);
}

TEST(DatasetLog, ReadBackEqualsWhatWasWrittenAcrossFiles) {
  const fs::path dir = scratchDir("across");
  std::vector<EpisodeRecord> eps;
  for (int k = 0; k < 5; ++k) eps.push_back(randomEpisode(100 + k, 40 + 37 * k, k < 3 ? "first" : "second", k % 2 == 0));
  {
    DatasetLogWriter a((dir / "a.lcmlog").string(), 32);
    for (int k = 0; k < 3; ++k) a.write(eps[k]);
  }
  // The fourth episode is split over the two files, as lcm-logger's --split-mb may cut it.
  {
    lcm::LogFile b((dir / "b.lcmlog").string(), "w");
    auto msgs = episodeMessages(eps[3], 32, 1);
    for (size_t i = 0; i + 1 < msgs.size(); ++i) writeRawEvent(b, transport::kDatasetChannel, encode(msgs[i]));
    lcm::LogFile c((dir / "c.lcmlog").string(), "w");
    writeRawEvent(c, transport::kDatasetChannel, encode(msgs.back()));
    writeRawEvent(c, "SOME_OTHER_CHANNEL", {1, 2, 3});
    for (auto& m : episodeMessages(eps[4], 32, 1)) writeRawEvent(c, transport::kDatasetChannel, encode(m));
  }
  LogReadReport report;
  const TransitionDataset d =
      readDatasetLogs({(dir / "a.lcmlog").string(), (dir / "b.lcmlog").string(), (dir / "c.lcmlog").string()}, &report);
  expectDatasetHolds(d, eps);
  EXPECT_EQ(d.task, "toy");
  EXPECT_EQ(d.policy_names, (std::vector<std::string>{"first", "second"}));
  EXPECT_EQ(report.files, 3);
  EXPECT_EQ(report.episodes, 5);
  EXPECT_EQ(report.other_channel, 1);
  EXPECT_EQ(report.rejectedTotal(), 0) << report.summary();
  // And back to records: the inverse of the reader.
  const auto back = datasetEpisodes(d);
  ASSERT_EQ(back.size(), eps.size());
  for (size_t k = 0; k < eps.size(); ++k) {
    EXPECT_EQ(back[k].obs, eps[k].obs);
    EXPECT_EQ(back[k].rewards, eps[k].rewards);
    EXPECT_EQ(back[k].terminated, eps[k].terminated);
  }
}

TEST(DatasetLog, TruncatedLastFileIsReportedAndItsBrokenTailSkipped) {
  const fs::path dir = scratchDir("truncated");
  std::vector<EpisodeRecord> eps;
  for (int k = 0; k < 4; ++k) eps.push_back(randomEpisode(200 + k, 50, "p", false));
  {
    DatasetLogWriter a((dir / "a.lcmlog").string(), 20);
    a.write(eps[0]);
    a.write(eps[1]);
    DatasetLogWriter b((dir / "b.lcmlog").string(), 20);
    b.write(eps[2]);
    b.write(eps[3]);
  }
  const fs::path b = dir / "b.lcmlog";
  fs::resize_file(b, fs::file_size(b) - 100);  // a recorder killed mid-write
  LogReadReport report;
  const TransitionDataset d = readDatasetLogs({(dir / "a.lcmlog").string(), b.string()}, &report);
  expectDatasetHolds(d, {eps[0], eps[1], eps[2]});
  EXPECT_EQ(report.rejected["damaged or truncated log tail"], 1) << report.summary();
  // The cut episode's messages before the cut have no seal after them: refused, not half-read.
  EXPECT_EQ(report.rejected["unsealed events after the last seal (a recording cut short)"], 2) << report.summary();
  ASSERT_FALSE(report.notes.empty());
  EXPECT_NE(report.notes[0].find("b.lcmlog"), std::string::npos) << report.notes[0];
  EXPECT_NE(report.notes[0].find("truncated event"), std::string::npos) << report.notes[0];
}

TEST(DatasetLog, HostileEventsAreRefusedAndChangeNothing) {
  const fs::path dir = scratchDir("hostile");
  const EpisodeRecord good = randomEpisode(300, 30, "p", true), other = randomEpisode(301, 30, "p", false);
  {
    lcm::LogFile log((dir / "h.lcmlog").string(), "w");
    auto msgs = episodeMessages(good, 10, 1);
    writeRawEvent(log, transport::kDatasetChannel, {0xde, 0xad, 0xbe, 0xef});  // garbage
    auto bytes = encode(msgs[0]);
    bytes.resize(bytes.size() - 7);  // cut short
    writeRawEvent(log, transport::kDatasetChannel, bytes);
    masa::lcmt_transitions nan = msgs[0];
    nan.obs[3] = std::numeric_limits<float>::quiet_NaN();
    writeRawEvent(log, transport::kDatasetChannel, encode(nan));
    masa::lcmt_transitions wrong_dims = msgs[0];
    wrong_dims.obs_dim = 4;  // obs_len no longer (n + 1) * obs_dim
    writeRawEvent(log, transport::kDatasetChannel, encode(wrong_dims));
    masa::lcmt_transitions early_end = msgs[0];
    early_end.terminated = true;  // termination on a message that is not the last
    writeRawEvent(log, transport::kDatasetChannel, encode(early_end));
    masa::lcmt_transitions headless = msgs[1];
    headless.episode_id = 999;  // a middle without its start
    writeRawEvent(log, transport::kDatasetChannel, encode(headless));
    for (auto& m : msgs) writeRawEvent(log, transport::kDatasetChannel, encode(m));
    for (auto& m : msgs) writeRawEvent(log, transport::kDatasetChannel, encode(m));  // replayed twice
    // An episode whose messages come out of order is dropped whole.
    auto shuffled = episodeMessages(other, 10, 1);
    writeRawEvent(log, transport::kDatasetChannel, encode(shuffled[0]));
    writeRawEvent(log, transport::kDatasetChannel, encode(shuffled[2]));
    writeRawEvent(log, transport::kDatasetChannel, encode(shuffled[1]));
  }
  LogReadReport report;
  const TransitionDataset d = readDatasetLogs({(dir / "h.lcmlog").string()}, &report);
  expectDatasetHolds(d, {good});
  EXPECT_EQ(report.rejected["malformed message (wrong_type)"] + report.rejected["malformed message (truncated)"], 2)
      << report.summary();
  EXPECT_EQ(report.rejected["duplicate of a complete episode"], 3) << report.summary();
  EXPECT_EQ(report.rejected["episode without its start"], 2) << report.summary();  // 999, and shuffled[1] after the drop
  EXPECT_EQ(report.rejected["out-of-order or foreign message in an episode (the episode is dropped)"], 1) << report.summary();
  int inconsistent = 0;
  for (const auto& [reason, count] : report.rejected)
    if (reason.rfind("inconsistent message", 0) == 0) inconsistent += static_cast<int>(count);
  EXPECT_EQ(inconsistent, 3) << report.summary();
}

TEST(DatasetLog, BadInputGetsAClearError) {
  const fs::path dir = scratchDir("bad");
  EXPECT_THROW(
      {
        try {
          readDatasetLogs({(dir / "missing.lcmlog").string()});
        } catch (const std::runtime_error& e) {
          EXPECT_NE(std::string(e.what()).find("missing.lcmlog"), std::string::npos) << e.what();
          throw;
        }
      },
      std::runtime_error);
  std::ofstream((dir / "text.lcmlog").string()) << "this is not a log, it is a text file with some words in it\n";
  EXPECT_THROW(readDatasetLogs({(dir / "text.lcmlog").string()}), std::runtime_error);
  // Two tasks in one read.
  {
    DatasetLogWriter a((dir / "a.lcmlog").string());
    a.write(randomEpisode(1, 10, "p", true));
    EpisodeRecord other = randomEpisode(2, 10, "p", true);
    other.task = "another_task";
    DatasetLogWriter b((dir / "b.lcmlog").string());
    b.write(other);
  }
  try {
    readDatasetLogs({(dir / "a.lcmlog").string(), (dir / "b.lcmlog").string()});
    ADD_FAILURE() << "logs of two tasks were read as one dataset";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("another_task"), std::string::npos) << e.what();
  }
  // A log with events, none of them a complete episode.
  {
    lcm::LogFile log((dir / "empty.lcmlog").string(), "w");
    writeRawEvent(log, "OTHER", {1});
  }
  EXPECT_THROW(readDatasetLogs({(dir / "empty.lcmlog").string()}), std::runtime_error);
}

TEST(DatasetHdf5, ExportReadsBackExactly) {
  const fs::path dir = scratchDir("hdf5");
  std::vector<EpisodeRecord> eps = {randomEpisode(1, 20, "a", true), randomEpisode(2, 33, "b", false)};
  {
    DatasetLogWriter w((dir / "x.lcmlog").string());
    for (const auto& e : eps) w.write(e);
  }
  const TransitionDataset d = readDatasetLogs({(dir / "x.lcmlog").string()});
  writeHdf5((dir / "x.h5").string(), d, "x.lcmlog");
  const TransitionDataset back = readHdf5((dir / "x.h5").string());
  expectDatasetHolds(back, eps);
  EXPECT_EQ(back.task, d.task);
  EXPECT_EQ(back.policy_names, d.policy_names);
  for (size_t k = 0; k < eps.size(); ++k) EXPECT_DOUBLE_EQ(back.episodes[k].ret, d.episodes[k].ret);
  EXPECT_FALSE(fs::exists(dir / "x.h5.tmp"));
  EXPECT_THROW(readHdf5((dir / "x.lcmlog").string()), std::runtime_error);  // not HDF5
  EXPECT_THROW(readHdf5((dir / "none.h5").string()), std::runtime_error);
}

TEST(DatasetRecorder, EpisodesAreTheEvaluatorsAndRepeatFromTheSeed) {
  policy::LoadedPolicy p = policy::loadPolicyFile(std::string(MASA_SOURCE_DIR) + "/tasks/a1_beam/policy/policy.bin");
  task::TaskFactory factory(task::taskCatalog(), p.config.task, p.spec, p.config.env, p.config.origin);
  RecordOptions o;
  o.eval.episodes = 3;
  o.eval.seed = 11;
  o.eval.max_steps = 40;
  o.policy_name = "shipped";
  std::vector<EpisodeRecord> first, second;
  const task::EvalSummary s = recordEpisodes(factory, *p.model, o, [&](const EpisodeRecord& e) { first.push_back(e); });
  recordEpisodes(factory, *p.model, o, [&](const EpisodeRecord& e) { second.push_back(e); });
  ASSERT_EQ(first.size(), 3u);
  ASSERT_EQ(second.size(), 3u);
  for (size_t k = 0; k < first.size(); ++k) {
    const EpisodeRecord& e = first[k];
    EXPECT_EQ(e.task, "a1_beam");
    EXPECT_EQ(e.obs, second[k].obs) << "the same seed must give the same episode";
    EXPECT_EQ(e.actions, second[k].actions);
    // Episodes end in any order; find this one's summary by its seed.
    const uint64_t seed = static_cast<uint64_t>(e.episode_id) & 0xffffffffu;
    ASSERT_GE(seed, 11u);
    ASSERT_LT(seed, 14u);
    const task::EpisodeResult& r = s.episodes[seed - 11];
    EXPECT_EQ(e.episode_id, episodeId("shipped", seed));
    EXPECT_EQ(e.length(), r.length);
    double ret = 0;
    for (float x : e.rewards) ret += x;
    EXPECT_NEAR(ret, r.ret, 1e-4 * (1 + std::abs(r.ret)));
    EXPECT_EQ(e.terminated, r.terminated);
    EXPECT_EQ(e.truncated, !r.terminated);
    EXPECT_EQ(e.obs.rows(), 47);
    EXPECT_TRUE(e.obs.allFinite());
  }
  // Sampled, not the mean: the actions differ from the mean action at the first observation.
  const Mat<float> mean = p.model->actMean(first[0].obs.leftCols(1));
  EXPECT_GT((mean - first[0].actions.leftCols(1)).norm(), 1e-3);
}

}  // namespace
}  // namespace masa::dataset
