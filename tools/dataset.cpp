// masa_dataset: offline datasets as LCM logs (channel MASA_DATASET, lcmt_transitions).
//   masa_dataset record tasks/a1_beam/policy/policy.bin --episodes 100 --out a1_expert.lcmlog
//   masa_dataset record runs/x --episodes 20 --out x.lcmlog --publish      (also on LCM: lcm-spy, lcm-logger)
//   masa_dataset info a1_expert.lcmlog more.lcmlog                        (what several logs hold together)
//   masa_dataset export a1_expert.lcmlog --hdf5 a1_expert.h5              (for h5py)
//   masa_dataset families runs/a1_run --episodes 200 --out datasets/a1    (expert, half_expert, weak_expert, mixed)
// Episodes are sampled from the policy (--mean: its mean action); episode k resets from seed + k.
#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>
#include <regex>

#include "common/core/build_info.hpp"
#include "common/core/config_error.hpp"
#include "common/dataset/dataset_log.hpp"
#include "common/dataset/hdf5_export.hpp"
#include "common/dataset/policy_recorder.hpp"
#include "common/policy/policy_file.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/lcm_url.hpp"
#include "common/transport/transport.hpp"
#include "tasks/tasks.hpp"

using namespace masa;
namespace fs = std::filesystem;

namespace {

// A run directory (its policy.bin) or a policy file.
std::string policyPath(const std::string& target) {
  fs::path p = fs::absolute(target);
  if (!fs::exists(p)) throw std::runtime_error(target + ": no such file or directory");
  if (fs::is_directory(p)) p /= "policy.bin";
  if (!fs::exists(p)) throw std::runtime_error(target + ": a directory without policy.bin (train it, or name a policy file)");
  if (!policy::isPolicyFile(p.string()))
    throw std::runtime_error(p.string() + ": not a masa policy file (a learner checkpoint? masa_eval --save-policy makes one)");
  return p.string();
}

struct Recording {
  int64_t episodes = 0, transitions = 0;
  double seconds = 0;
  task::EvalSummary summary;
};

// Records `episodes` episodes of one policy into `writer` (and onto LCM when `lcm` is given).
Recording recordPolicy(const std::string& policy_file, const std::string& name, int episodes, uint64_t seed,
                       bool mean, int threads, dataset::DatasetLogWriter& writer, lcm::LCM* lcm, int max_steps = 0) {
  policy::LoadedPolicy p = policy::loadPolicyFile(policy_file);
  task::TaskFactory factory(task::taskCatalog(), p.config.task, p.spec, p.config.env, p.config.origin);
  dataset::RecordOptions o;
  o.eval.episodes = episodes;
  o.eval.seed = seed;
  o.eval.deterministic = mean;
  o.eval.threads = threads;
  o.eval.max_steps = max_steps;
  o.policy_name = name;
  Recording r;
  const auto t0 = std::chrono::steady_clock::now();
  r.summary = dataset::recordEpisodes(factory, *p.model, o, [&](const dataset::EpisodeRecord& e) {
    writer.write(e);
    if (lcm)  // 128 steps a message: about 30 KB, well under LCM's fragmenting size
      for (masa::lcmt_transitions& m : dataset::episodeMessages(e, 128, transport::wallClockMicros())) lcm->publish(transport::kDatasetChannel, &m);
    ++r.episodes;
    r.transitions += e.length();
  });
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

// Summary numbers of a dataset (or of the episodes of one policy in it).
struct DatasetStats {
  int64_t episodes = 0, transitions = 0;
  double mean_return = 0, std_return = 0;
  double success_rate = -1;
};

DatasetStats statsOf(const dataset::TransitionDataset& d, int policy = -1) {
  DatasetStats s;
  std::vector<double> returns;
  int measured = 0, succeeded = 0;
  for (const dataset::EpisodeInfo& e : d.episodes) {
    if (policy >= 0 && e.policy_id != policy) continue;
    returns.push_back(e.ret);
    s.transitions += e.length;
    if (e.success >= 0) ++measured;
    if (e.success == 1) ++succeeded;
  }
  s.episodes = static_cast<int64_t>(returns.size());
  if (returns.empty()) return s;
  s.mean_return = std::accumulate(returns.begin(), returns.end(), 0.0) / static_cast<double>(returns.size());
  double q = 0;
  for (double r : returns) q += (r - s.mean_return) * (r - s.mean_return);
  s.std_return = returns.size() > 1 ? std::sqrt(q / static_cast<double>(returns.size() - 1)) : 0.0;
  s.success_rate = measured > 0 ? static_cast<double>(succeeded) / measured : -1.0;
  return s;
}

void printInfo(const dataset::TransitionDataset& d, const dataset::LogReadReport& report) {
  std::printf("%s", report.summary().c_str());
  const DatasetStats all = statsOf(d);
  std::printf("task %s, obs %d, act %d: %lld episodes, %lld transitions, return %.3f +- %.3f", d.task.c_str(), d.obs_dim,
              d.act_dim, static_cast<long long>(all.episodes), static_cast<long long>(all.transitions), all.mean_return,
              all.std_return);
  if (all.success_rate >= 0) std::printf(", success %.3f", all.success_rate);
  std::printf("\n");
  for (size_t i = 0; i < d.policy_names.size(); ++i) {
    const DatasetStats s = statsOf(d, static_cast<int>(i));
    std::printf("  policy %zu %s: %lld episodes, return %.3f +- %.3f", i, d.policy_names[i].c_str(),
                static_cast<long long>(s.episodes), s.mean_return, s.std_return);
    if (s.success_rate >= 0) std::printf(", success %.3f", s.success_rate);
    std::printf("\n");
  }
}

// The kept stages of a run (policies/policy_uNNNNNN.bin), by update.
std::vector<std::pair<int, std::string>> snapshotsOf(const fs::path& run) {
  std::vector<std::pair<int, std::string>> out;
  const fs::path dir = run / "policies";
  if (!fs::is_directory(dir)) return out;
  const std::regex name("policy_u([0-9]+)\\.bin");
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string file = entry.path().filename().string();
    if (std::regex_match(file, m, name)) out.emplace_back(std::stoi(m[1].str()), entry.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool sameBytes(const std::string& a, const std::string& b) {
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  return std::equal(std::istreambuf_iterator<char>(fa), std::istreambuf_iterator<char>(),
                    std::istreambuf_iterator<char>(fb), std::istreambuf_iterator<char>());
}

std::string relativeName(const fs::path& file, const fs::path& run) {
  return (run.filename() / fs::relative(file, run)).string();
}

// The four families of the TriFinger offline benchmark, from one training run.
int buildFamilies(const std::string& run_arg, const std::string& out_arg, int episodes, uint64_t seed, bool mean,
                  int threads, const std::string& weak_arg) {
  const fs::path run = fs::absolute(run_arg);
  const std::string expert = policyPath(run.string());
  const auto snapshots = snapshotsOf(run);
  if (snapshots.size() < 2)
    throw std::runtime_error(run_arg + " keeps " + std::to_string(snapshots.size()) +
                             " policy stages (policies/policy_u*.bin); the mixed family needs several: train with "
                             "--set runner.snapshot_every=N");
  std::string weak = weak_arg.empty() ? std::string() : policyPath(weak_arg);
  if (weak.empty()) {  // the stage nearest a quarter of the run
    const int target = snapshots.back().first / 4;
    weak = std::min_element(snapshots.begin(), snapshots.end(), [&](const auto& a, const auto& b) {
             return std::abs(a.first - target) < std::abs(b.first - target);
           })->second;
  }
  fs::create_directories(out_arg);
  const fs::path out = fs::absolute(out_arg);
  auto progress = [](const char* family, const std::string& name, const Recording& r) {
    std::printf("  %-12s %-44s %5lld episodes %8lld steps  return %9.3f  %5.1f s\n", family, name.c_str(),
                static_cast<long long>(r.episodes), static_cast<long long>(r.transitions), r.summary.ret.mean, r.seconds);
    std::fflush(stdout);
  };
  std::printf("masa_dataset families: %s, %d episodes a family, expert %s, weak %s, %zu stages\n", run_arg.c_str(),
              episodes, expert.c_str(), weak.c_str(), snapshots.size());
  // expert: the final policy.
  {
    dataset::DatasetLogWriter w((out / "expert.lcmlog").string());
    const std::string name = run.filename().string() + "/policy.bin";
    progress("expert", name, recordPolicy(expert, name, episodes, seed, mean, threads, w, nullptr));
  }
  const dataset::TransitionDataset expert_data = dataset::readDatasetLogs({(out / "expert.lcmlog").string()});
  const auto expert_episodes = dataset::datasetEpisodes(expert_data);
  // half_expert: a seeded random half of the expert's episodes.
  {
    std::vector<size_t> order(expert_episodes.size());
    std::iota(order.begin(), order.end(), size_t{0});
    Rng rng(seed);
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(order.size() / 2);
    std::sort(order.begin(), order.end());
    dataset::DatasetLogWriter w((out / "half_expert.lcmlog").string());
    for (size_t i : order) w.write(expert_episodes[i]);
  }
  // weak_expert: half the episodes from a weak stage, half the expert's.
  {
    dataset::DatasetLogWriter w((out / "weak_expert.lcmlog").string());
    const int half = episodes / 2;
    for (int i = 0; i < episodes - half; ++i) w.write(expert_episodes[static_cast<size_t>(i)]);
    progress("weak_expert", relativeName(weak, run),
             recordPolicy(weak, relativeName(weak, run), half, seed + static_cast<uint64_t>(episodes), mean, threads, w, nullptr));
  }
  // mixed: the stages of the run and its final policy, equal shares.
  {
    dataset::DatasetLogWriter w((out / "mixed.lcmlog").string());
    std::vector<std::string> stages;
    for (const auto& s : snapshots)
      if (!sameBytes(s.second, expert)) stages.push_back(s.second);  // the last stage is often the final policy
    stages.push_back(expert);
    const int n = static_cast<int>(stages.size());
    for (int i = 0; i < n; ++i) {
      const int share = episodes / n + (i < episodes % n ? 1 : 0);
      if (share == 0) continue;
      const std::string name = i + 1 == n ? run.filename().string() + "/policy.bin" : relativeName(stages[i], run);
      progress("mixed", name,
               recordPolicy(stages[i], name, share, seed + 2 * static_cast<uint64_t>(episodes) + static_cast<uint64_t>(i) * episodes,
                            mean, threads, w, nullptr));
    }
  }
  // The table: sizes, mean return, success.
  std::ofstream md(out / "families.md"), csv(out / "families.csv");
  md << "# Offline datasets of " << run_arg << "\n\n"
     << "Built by `masa_dataset families " << run_arg << " --episodes " << episodes << " --seed " << seed
     << (weak_arg.empty() ? "" : " --weak " + weak_arg) << (mean ? " --mean" : "") << "`; task " << expert_data.task << ", expert `" << expert << "`, weak `" << weak
     << "`.\n\n| family | episodes | transitions | policies | return mean | return std | success |\n"
     << "|---|---:|---:|---:|---:|---:|---:|\n";
  csv << "family,file,episodes,transitions,policies,return_mean,return_std,success_rate,bytes\n";
  for (const char* family : {"expert", "half_expert", "weak_expert", "mixed"}) {
    const fs::path file = out / (std::string(family) + ".lcmlog");
    const dataset::TransitionDataset d = dataset::readDatasetLogs({file.string()});
    const DatasetStats s = statsOf(d);
    char line[256];
    std::snprintf(line, sizeof line, "| %s | %lld | %lld | %zu | %.3f | %.3f | %s |\n", family,
                  static_cast<long long>(s.episodes), static_cast<long long>(s.transitions), d.policy_names.size(),
                  s.mean_return, s.std_return, s.success_rate >= 0 ? std::to_string(s.success_rate).c_str() : "n/a");
    md << line;
    csv << family << ',' << file.filename().string() << ',' << s.episodes << ',' << s.transitions << ','
        << d.policy_names.size() << ',' << s.mean_return << ',' << s.std_return << ',' << s.success_rate << ','
        << fs::file_size(file) << '\n';
  }
  md.close();
  std::ifstream table(out / "families.md");
  std::cout << table.rdbuf();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Offline datasets of masa: record, inspect, export (LCM logs on channel MASA_DATASET)"};
  app.set_version_flag("--version", masa::buildCommit());
  app.require_subcommand(1);
  uint64_t seed = 0;
  int episodes = 100, threads = 1;
  bool mean = false;

  std::string target, out, name, publish_url;
  bool publish = false;
  int max_steps = 0;
  CLI::App* record = app.add_subcommand("record", "record a policy's episodes into a new LCM log");
  record->add_option("policy", target, "policy file or run directory (its policy.bin)")->required();
  record->add_option("--out", out, "the log to write")->required();
  record->add_option("--episodes", episodes, "episodes")->capture_default_str()->check(CLI::PositiveNumber);
  record->add_option("--seed", seed, "episode k resets from seed + k")->capture_default_str();
  record->add_flag("--mean", mean, "act with the policy mean (default: sample, as a behaviour policy)");
  record->add_option("--max-steps", max_steps, "cut episodes after this many steps, as a time limit (0: the task's)");
  record->add_option("--threads", threads, "threads stepping the environments")->capture_default_str()->check(CLI::Range(1, 1024));
  record->add_option("--name", name, "policy name recorded with the episodes (default: the file's path)");
  record->add_flag("--publish", publish, "also publish the messages on LCM (see them in lcm-spy, record with lcm-logger)");
  record->add_option("--url", publish_url, "LCM URL for --publish (default: MASA_LCM_URL or the loopback one)");

  std::vector<std::string> logs;
  std::string hdf5;
  CLI::App* info = app.add_subcommand("info", "what one or more logs hold together");
  info->add_option("logs", logs, "LCM logs")->required();
  CLI::App* exporter = app.add_subcommand("export", "write one or more logs as one HDF5 file");
  exporter->add_option("logs", logs, "LCM logs")->required();
  exporter->add_option("--hdf5", hdf5, "the HDF5 file to write")->required();

  std::string run, weak;
  CLI::App* families = app.add_subcommand("families", "expert, half_expert, weak_expert and mixed datasets of one run");
  families->add_option("run", run, "run directory with policy.bin and policies/policy_u*.bin")->required();
  families->add_option("--out", out, "directory for the four logs and families.md")->required();
  families->add_option("--episodes", episodes, "episodes a family")->capture_default_str()->check(CLI::PositiveNumber);
  families->add_option("--seed", seed, "first reset seed")->capture_default_str();
  families->add_option("--weak", weak, "the weak policy (default: the run's stage nearest a quarter of its updates)");
  families->add_flag("--mean", mean, "act with the policy mean (default: sample)");
  families->add_option("--threads", threads, "threads stepping the environments")->capture_default_str()->check(CLI::Range(1, 1024));
  CLI11_PARSE(app, argc, argv);

  try {
    if (*record) {
      const std::string file = policyPath(target);
      if (name.empty()) name = target;
      std::unique_ptr<lcm::LCM> lcm;
      if (publish) {
        if (publish_url.empty()) publish_url = std::getenv("MASA_LCM_URL") ? std::getenv("MASA_LCM_URL") : transport::loopbackUrl();
        lcm = std::make_unique<lcm::LCM>(publish_url);
        if (!lcm->good()) throw std::runtime_error("cannot open LCM at " + publish_url);
      }
      dataset::DatasetLogWriter writer(out);
      const Recording r = recordPolicy(file, name, episodes, seed, mean, threads, writer, lcm.get(), max_steps);
      std::printf("recorded %lld episodes (%lld transitions) of %s into %s in %.1f s%s\n%s",
                  static_cast<long long>(r.episodes), static_cast<long long>(r.transitions), name.c_str(), out.c_str(),
                  r.seconds, publish ? (", also published on " + publish_url).c_str() : "",
                  task::formatSummary(r.summary).c_str());
    } else if (*info) {
      dataset::LogReadReport report;
      const dataset::TransitionDataset d = dataset::readDatasetLogs(logs, &report);
      printInfo(d, report);
    } else if (*exporter) {
      dataset::LogReadReport report;
      const dataset::TransitionDataset d = dataset::readDatasetLogs(logs, &report);
      std::string source;
      for (const std::string& l : logs) source += (source.empty() ? "" : " ") + l;
      dataset::writeHdf5(hdf5, d, source);
      std::printf("%swrote %s (%lld transitions)\n", report.summary().c_str(), hdf5.c_str(),
                  static_cast<long long>(d.size()));
    } else if (*families) {
      return buildFamilies(run, out, episodes, seed, mean, threads, weak);
    }
  } catch (const ConfigError& e) {
    std::cerr << "masa_dataset: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "masa_dataset: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
