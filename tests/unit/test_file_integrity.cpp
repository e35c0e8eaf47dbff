// Each file reader against damage (issue #33, item 3): a single bit flipped at every byte of a
// policy file, a learner checkpoint and a dataset log is refused by the reader the tools use
// (masa_eval, masa_deploy, masa_train --resume, masa_offline), naming the file; random mutations
// of every kind (file_mutations.hpp, seeded) never crash a reader and never get a damaged payload
// accepted; an unsealed policy file from before the seal loads with a one-line warning.
// (The actor's environments file: test_actor_environments.cpp.)
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>

#include "common/config/run_config.hpp"
#include "common/dataset/dataset_log.hpp"
#include "common/dataset/hdf5_export.hpp"
#include "common/policy/policy_file.hpp"
#include "common/transport/channels.hpp"
#include "file_mutations.hpp"
#include "common/nn/adam.hpp"
#include "learner/run_dir/checkpoint.hpp"

namespace masa {
namespace {

namespace fs = std::filesystem;

fs::path integrityDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("masa_file_integrity_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string fileBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string flipped(std::string bytes, std::size_t at) {
  bytes[at] ^= static_cast<char>(1u << (at % 8));
  return bytes;
}

// What `load(path)` threw, "" when it accepted the file.
template <class Load>
std::string refusal(const Load& load, const fs::path& path) {
  try {
    load(path.string());
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// Keeps stderr (the readers' warnings) off the test's output; released on every way out, a failed
// assertion's too, so that the next test can capture again.
struct QuietStderr {
  QuietStderr() { ::testing::internal::CaptureStderr(); }
  ~QuietStderr() { ::testing::internal::GetCapturedStderr(); }
};

config::RunConfig smallA1Config(const std::string& method) {
  return config::loadRunConfig(config::defaultConfigsDir(), {"task=a1_beam", "method=" + method, "model.policy_hidden=[16]",
                                                             "model.critic_hidden=[16]"});
}

struct SmallModel {
  explicit SmallModel(const config::RunConfig& rc) : spec(sym::SymmetrySpec::load(rc.spec_path)), model(spec, rc.model) {
    Rng rng(3);
    model.initialize(rng);
  }
  sym::SymmetrySpec spec;
  model::ActorCritic<float> model;
};

// ---- policy files: what masa_eval, masa_export and masa_deploy read ----

TEST(PolicyFileIntegrity, ABitFlippedAtAnyByteIsRefusedNamingTheFile) {
  const fs::path dir = integrityDir("policy_every_byte");
  const config::RunConfig rc = smallA1Config("masa");
  SmallModel m(rc);
  const fs::path good = dir / "policy.bin", bad = dir / "damaged.bin";
  policy::savePolicyFile(good.string(), rc, m.model);
  const std::string bytes = fileBytes(good);
  const auto load = [](const std::string& p) { policy::loadPolicyFile(p); };
  ASSERT_EQ(refusal(load, good), "");
  writeBytes(bad, bytes);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    fuzz::flipBitInFile(bad.string(), i);
    const std::string why = refusal(load, bad);
    ASSERT_NE(why, "") << "a policy file with byte " << i << " of " << bytes.size() << " flipped was loaded";
    ASSERT_EQ(why.rfind(bad.string() + ": ", 0), 0u) << why;
    fuzz::flipBitInFile(bad.string(), i);
  }
  writeBytes(bad, flipped(bytes, bytes.size() / 2));
  EXPECT_EQ(refusal(load, bad), bad.string() + ": checksum mismatch (file corrupted or truncated)");
}

TEST(PolicyFileIntegrity, ABitFlippedInTheShippedA1PolicyIsRefused) {
  const fs::path shipped = fs::path(MASA_SOURCE_DIR) / "tasks/a1_beam/policy/policy.bin";
  const std::string bytes = fileBytes(shipped);
  const fs::path bad = integrityDir("shipped") / "policy.bin";
  const auto load = [](const std::string& p) { policy::loadPolicyFile(p); };
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(refusal(load, shipped), "");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << "the shipped policy is sealed: no warning";
  int checked = 0;
  writeBytes(bad, bytes);
  for (std::size_t i = 0; i < bytes.size(); i += (i < 512 || i + 512 > bytes.size()) ? 1 : 409, ++checked) {
    fuzz::flipBitInFile(bad.string(), i);
    ASSERT_NE(refusal(load, bad), "") << "byte " << i;
    fuzz::flipBitInFile(bad.string(), i);
  }
  EXPECT_GT(checked, 1800);
}

TEST(PolicyFileIntegrity, AnUnsealedPolicyFromBeforeTheSealLoadsWithAWarningOrIsRefusedWhenSignedIsRequired) {
  const fs::path dir = integrityDir("policy_legacy");
  const config::RunConfig rc = smallA1Config("sa");
  SmallModel m(rc);
  policy::savePolicyFile((dir / "sealed.bin").string(), rc, m.model);
  // The old format is the seal's payload: what stands after the 52-byte header and the kind.
  const std::string sealed = fileBytes(dir / "sealed.bin");
  const std::size_t payload_at = 52 + 4 + policy::kPolicyFileKind.name.size();
  ASSERT_EQ(sealed.compare(payload_at, 8, "MASAPOL1"), 0);
  const fs::path old = dir / "old_policy.bin";
  writeBytes(old, sealed.substr(payload_at));
  ASSERT_TRUE(policy::isPolicyFile(old.string()));
  ::testing::internal::CaptureStderr();
  const policy::LoadedPolicy p = policy::loadPolicyFile(old.string());
  const std::string warning = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(warning.find("warning: " + old.string() + ": written before masa sealed its files"), std::string::npos) << warning;
  EXPECT_EQ(p.model->params().values(), m.model.params().values());
  EXPECT_NE(p.integrity.find("unsealed"), std::string::npos);
  integrity::TrustedKeys none;
  integrity::ReadRules rules;
  rules.require_signed_by = &none;
  const auto load_signed = [&](const std::string& path) { policy::loadPolicyFile(path, config::defaultConfigsDir(), rules); };
  EXPECT_NE(refusal(load_signed, old).find("not signed"), std::string::npos);
  EXPECT_NE(refusal(load_signed, dir / "sealed.bin").find("not signed"), std::string::npos);
}

TEST(PolicyFileIntegrity, RandomMutationsNeverCrashTheReaderNorGetAccepted) {
  const fs::path dir = integrityDir("policy_fuzz");
  const config::RunConfig rc = smallA1Config("masa");
  SmallModel m(rc);
  policy::savePolicyFile((dir / "policy.bin").string(), rc, m.model);
  const std::string bytes = fileBytes(dir / "policy.bin");
  const auto load = [](const std::string& p) { policy::loadPolicyFile(p); };
  std::mt19937_64 rng(33);
  for (int i = 0; i < 300; ++i) {
    const fuzz::FileMutation mut = fuzz::mutateFile(bytes, rng);
    if (mut.bytes == bytes) continue;
    writeBytes(dir / "mutated.bin", mut.bytes);
    ASSERT_NE(refusal(load, dir / "mutated.bin"), "") << "mutation " << i << " (" << mut.what << ") was accepted";
  }
}

// ---- learner checkpoints: what masa_train --resume, masa_learner and masa_eval read ----

struct SmallCheckpoint {
  SmallCheckpoint() : rc(smallA1Config("masa")), m(rc), adam(m.model.params()) {
    state.run_id = 7;
    state.updates = state.version = 3;
    state.env_steps = 1234;
    state.rng_state = "1 2 3";
    state.kind = "ppo";
    std::ostringstream body(std::ios::binary);
    m.model.save(body);
    adam.save(body);
    state.body = std::move(body).str();
  }
  config::RunConfig rc;
  SmallModel m;
  nn::Adam<float> adam;
  learner::CheckpointState state;
};

TEST(CheckpointIntegrity, ABitFlippedAtAnyByteIsRefusedAndTheRankZeroBytesToo) {
  const fs::path dir = integrityDir("checkpoint_every_byte");
  SmallCheckpoint ck;
  const fs::path good = dir / "checkpoint.bin", bad = dir / "damaged.bin";
  learner::writeCheckpoint(good.string(), ck.state);
  learner::CheckpointState into;
  const auto load = [&](const std::string& p) { into = learner::readCheckpoint(p); };
  ASSERT_EQ(refusal(load, good), "");
  EXPECT_EQ(into.body, ck.state.body);
  EXPECT_EQ(into.kind, "ppo");
  EXPECT_EQ(into.rng_state, ck.state.rng_state);
  const std::string bytes = fileBytes(good);
  writeBytes(bad, bytes);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    fuzz::flipBitInFile(bad.string(), i);
    const std::string why = refusal(load, bad);
    ASSERT_NE(why, "") << "a checkpoint with byte " << i << " of " << bytes.size() << " flipped was loaded";
    ASSERT_EQ(why.rfind(bad.string() + ": ", 0), 0u) << why;
    fuzz::flipBitInFile(bad.string(), i);
  }
  EXPECT_THROW(learner::readCheckpointBytes(flipped(bytes, 100), "rank 0's"), std::runtime_error);
  EXPECT_NO_THROW(learner::readCheckpointBytes(bytes, "rank 0's"));
}

TEST(CheckpointIntegrity, RandomMutationsNeverCrashTheReaderNorGetAccepted) {
  const fs::path dir = integrityDir("checkpoint_fuzz");
  SmallCheckpoint ck;
  learner::writeCheckpoint((dir / "checkpoint.bin").string(), ck.state);
  const std::string bytes = fileBytes(dir / "checkpoint.bin");
  const auto load = [&](const std::string& p) { learner::readCheckpoint(p); };
  std::mt19937_64 rng(34);
  for (int i = 0; i < 300; ++i) {
    const fuzz::FileMutation mut = fuzz::mutateFile(bytes, rng);
    if (mut.bytes == bytes) continue;
    writeBytes(dir / "mutated.bin", mut.bytes);
    ASSERT_NE(refusal(load, dir / "mutated.bin"), "") << "mutation " << i << " (" << mut.what << ") was accepted";
  }
}

// ---- dataset logs: what masa_dataset and masa_offline read ----

dataset::EpisodeRecord toyEpisode(int64_t id, int length) {
  Rng rng(static_cast<uint64_t>(id));
  std::normal_distribution<float> n(0.f, 1.f);
  dataset::EpisodeRecord e;
  e.task = "toy";
  e.episode_id = id;
  e.policy_name = "p";
  e.obs = Mat<float>::NullaryExpr(4, length + 1, [&] { return n(rng); });
  e.actions = Mat<float>::NullaryExpr(2, length, [&] { return n(rng); });
  for (int t = 0; t < length; ++t) e.rewards.push_back(n(rng));
  e.terminated = true;
  return e;
}

// Reads a damaged log: "" when every episode it accepted is one of `originals` exactly (refusing
// some or all is fine: a log is sealed episode by episode), else what was accepted wrongly.
std::string acceptedDamage(const fs::path& log, const std::vector<dataset::EpisodeRecord>& originals) {
  dataset::TransitionDataset d;
  try {
    d = dataset::readDatasetLogs({log.string()});
  } catch (const std::runtime_error&) {
    return "";
  }
  for (const dataset::EpisodeRecord& got : dataset::datasetEpisodes(d)) {
    const auto want = std::find_if(originals.begin(), originals.end(), [&](const auto& e) { return e.episode_id == got.episode_id; });
    if (want == originals.end()) return "an episode " + std::to_string(got.episode_id) + " that was never written";
    if (got.obs != want->obs || got.actions != want->actions || got.rewards != want->rewards || got.terminated != want->terminated ||
        got.truncated != want->truncated || got.success != want->success || got.policy_name != want->policy_name || d.task != "toy")
      return "episode " + std::to_string(got.episode_id) + " differs from what was written";
  }
  return "";
}

std::vector<dataset::EpisodeRecord> writeToyLog(const fs::path& path) {
  std::vector<dataset::EpisodeRecord> eps{toyEpisode(1, 12), toyEpisode(2, 7), toyEpisode(3, 9)};
  dataset::DatasetLogWriter w(path.string(), 5);
  for (const auto& e : eps) w.write(e);
  return eps;
}

TEST(DatasetLogIntegrity, ABitFlippedAtAnyByteNeverGetsADamagedEpisodeAccepted) {
  const fs::path dir = integrityDir("dataset_every_byte");
  const auto eps = writeToyLog(dir / "toy.lcmlog");
  dataset::LogReadReport report;
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(dataset::readDatasetLogs({(dir / "toy.lcmlog").string()}, &report).episodes.size(), 3u);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << "a sealed log: no warning";
  EXPECT_EQ(report.rejectedTotal(), 0) << report.summary();
  const std::string bytes = fileBytes(dir / "toy.lcmlog");
  int whole = 0;
  {
  QuietStderr quiet;
  writeBytes(dir / "damaged.lcmlog", bytes);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    fuzz::flipBitInFile((dir / "damaged.lcmlog").string(), i);
    const std::string wrong = acceptedDamage(dir / "damaged.lcmlog", eps);
    ASSERT_EQ(wrong, "") << "byte " << i << " of " << bytes.size() << " flipped: " << wrong;
    fuzz::flipBitInFile((dir / "damaged.lcmlog").string(), i);
  }
  }
  // A damaged episode costs itself only: one flipped in the second episode's data leaves two.
  std::string second = bytes;
  const std::size_t at = bytes.size() / 2;
  second[at] ^= 1;
  writeBytes(dir / "one_damaged.lcmlog", second);
  dataset::LogReadReport one;
  const auto d = dataset::readDatasetLogs({(dir / "one_damaged.lcmlog").string()}, &one);
  whole = static_cast<int>(d.episodes.size());
  EXPECT_EQ(whole, 2) << one.summary();
  EXPECT_GT(one.rejected["events whose seal fails (damaged log)"], 0) << one.summary();
}

TEST(DatasetLogIntegrity, RandomMutationsNeverCrashTheReaderNorGetADamagedEpisodeAccepted) {
  const fs::path dir = integrityDir("dataset_fuzz");
  const auto eps = writeToyLog(dir / "toy.lcmlog");
  const std::string bytes = fileBytes(dir / "toy.lcmlog");
  std::mt19937_64 rng(35);
  QuietStderr quiet;
  for (int i = 0; i < 300; ++i) {
    const fuzz::FileMutation mut = fuzz::mutateFile(bytes, rng);
    writeBytes(dir / "mutated.lcmlog", mut.bytes);
    const std::string wrong = acceptedDamage(dir / "mutated.lcmlog", eps);
    ASSERT_EQ(wrong, "") << "mutation " << i << " (" << mut.what << "): " << wrong;
  }
}

TEST(DatasetLogIntegrity, ALogWithoutSealsIsReadWithAWarningNamingIt) {
  const fs::path dir = integrityDir("dataset_unsealed");
  const dataset::EpisodeRecord e = toyEpisode(5, 6);
  {
    lcm::LogFile log((dir / "recorded.lcmlog").string(), "w");
    for (masa::lcmt_transitions& m : dataset::episodeMessages(e, 4, 1)) {
      std::vector<unsigned char> b(static_cast<size_t>(m.getEncodedSize()));
      m.encode(b.data(), 0, static_cast<int>(b.size()));
      lcm::LogEvent ev{0, 1, transport::kDatasetChannel, static_cast<int32_t>(b.size()), b.data()};
      ASSERT_EQ(log.writeEvent(&ev), 0);
    }
  }
  dataset::LogReadReport report;
  ::testing::internal::CaptureStderr();
  const auto d = dataset::readDatasetLogs({(dir / "recorded.lcmlog").string()}, &report);
  const std::string warning = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(d.episodes.size(), 1u);
  EXPECT_EQ(report.unsealed_files, 1);
  EXPECT_NE(warning.find((dir / "recorded.lcmlog").string() + ": an unsealed dataset log"), std::string::npos) << warning;
}

// ---- HDF5 exports: what masa's own HDF5 reader accepts (h5py checks the Fletcher-32 of each chunk) ----

// "" when `path` is refused or read back as `want` exactly.
std::string acceptedHdf5Damage(const fs::path& path, const dataset::TransitionDataset& want) {
  dataset::TransitionDataset got;
  try {
    got = dataset::readHdf5(path.string());
  } catch (const std::runtime_error&) {
    return "";
  }
  const bool same = got.obs == want.obs && got.next_obs == want.next_obs && got.actions == want.actions && got.rewards == want.rewards &&
                    got.terminals == want.terminals && got.timeouts == want.timeouts && got.task == want.task &&
                    got.policy_names == want.policy_names && got.episodes.size() == want.episodes.size();
  return same ? "" : "a damaged export was read as a different dataset";
}

TEST(Hdf5ExportIntegrity, FlippedBitsAndRandomDamageNeverGetADifferentDatasetAccepted) {
  const fs::path dir = integrityDir("hdf5");
  writeToyLog(dir / "toy.lcmlog");
  const dataset::TransitionDataset d = dataset::readDatasetLogs({(dir / "toy.lcmlog").string()});
  dataset::writeHdf5((dir / "toy.h5").string(), d, "toy.lcmlog");
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(dataset::readHdf5((dir / "toy.h5").string()).rewards, d.rewards) << "the intact export reads back";
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << "a sealed export: no warning";
  const std::string bytes = fileBytes(dir / "toy.h5");
  writeBytes(dir / "damaged.h5", bytes);
  for (std::size_t i = 0; i < bytes.size(); i += 7) {
    fuzz::flipBitInFile((dir / "damaged.h5").string(), i);
    ASSERT_EQ(acceptedHdf5Damage(dir / "damaged.h5", d), "") << "byte " << i << " of " << bytes.size() << " flipped";
    fuzz::flipBitInFile((dir / "damaged.h5").string(), i);
  }
  std::mt19937_64 rng(37);
  for (int i = 0; i < 100; ++i) {
    const fuzz::FileMutation mut = fuzz::mutateFile(bytes, rng);
    writeBytes(dir / "mutated.h5", mut.bytes);
    ASSERT_EQ(acceptedHdf5Damage(dir / "mutated.h5", d), "") << "mutation " << i << " (" << mut.what << ")";
  }
}

}  // namespace
}  // namespace masa
