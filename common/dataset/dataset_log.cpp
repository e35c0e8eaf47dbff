#include "common/dataset/dataset_log.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "common/dataset/log_seal.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/transport.hpp"
#include "common/transport/wire_guard.hpp"

namespace masa::dataset {
namespace {

constexpr uint32_t kLogSync = 0xEDA1DA01u;  // LCM log event marker (lcm/eventlog.c)
constexpr int32_t kMaxChannelBytes = 256;    // LCM's own channel name limit is 63
constexpr int32_t kMaxEventBytes = 1 << 30;

uint64_t bigEndian(const unsigned char* p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

// One episode being put together from its messages.
struct PartialEpisode {
  int32_t next_offset = 0;
  std::string policy_name;
  std::vector<float> obs, actions, rewards;  // obs without the final next observation
  std::vector<float> last_obs;               // the latest message's final observation
};

// Appends finished episodes to growing column buffers; the dataset is made once at the end.
class DatasetBuilder {
 public:
  void setShape(const masa::lcmt_transitions& m, const std::string& file) {
    if (task_.empty()) {
      task_ = m.task;
      obs_dim_ = m.obs_dim;
      act_dim_ = m.act_dim;
      first_file_ = file;
      return;
    }
    if (m.task != task_ || m.obs_dim != obs_dim_ || m.act_dim != act_dim_) {
      std::ostringstream os;
      os << "dataset logs of different tasks: " << file << " has " << m.task << " (obs " << m.obs_dim << ", act "
         << m.act_dim << "), " << first_file_ << " has " << task_ << " (obs " << obs_dim_ << ", act " << act_dim_
         << "); read them separately";
      throw std::runtime_error(os.str());
    }
  }

  void add(int64_t episode_id, PartialEpisode&& p, bool terminated, bool truncated, int8_t success) {
    EpisodeInfo e;
    e.episode_id = episode_id;
    e.policy_id = policyId(p.policy_name);
    e.start = static_cast<int64_t>(rewards_.size());
    e.length = static_cast<int32_t>(p.rewards.size());
    e.success = success;
    for (float r : p.rewards) e.ret += r;
    const size_t od = static_cast<size_t>(obs_dim_);
    obs_.insert(obs_.end(), p.obs.begin(), p.obs.end());
    next_obs_.insert(next_obs_.end(), p.obs.begin() + od, p.obs.end());
    next_obs_.insert(next_obs_.end(), p.last_obs.begin(), p.last_obs.end());
    actions_.insert(actions_.end(), p.actions.begin(), p.actions.end());
    rewards_.insert(rewards_.end(), p.rewards.begin(), p.rewards.end());
    terminals_.resize(rewards_.size(), 0);
    timeouts_.resize(rewards_.size(), 0);
    terminals_.back() = terminated;
    timeouts_.back() = truncated;
    episodes_.push_back(e);
  }

  TransitionDataset finish() {
    TransitionDataset d;
    d.task = task_;
    d.obs_dim = obs_dim_;
    d.act_dim = act_dim_;
    const Eigen::Index n = static_cast<Eigen::Index>(rewards_.size());
    d.obs = Eigen::Map<Mat<float>>(obs_.data(), obs_dim_, n);
    d.next_obs = Eigen::Map<Mat<float>>(next_obs_.data(), obs_dim_, n);
    d.actions = Eigen::Map<Mat<float>>(actions_.data(), act_dim_, n);
    d.rewards = Eigen::Map<Vec<float>>(rewards_.data(), n);
    d.terminals = std::move(terminals_);
    d.timeouts = std::move(timeouts_);
    d.episodes = std::move(episodes_);
    d.policy_names = std::move(policy_names_);
    d.validate();
    return d;
  }

  bool empty() const { return episodes_.empty(); }

 private:
  int32_t policyId(const std::string& name) {
    for (size_t i = 0; i < policy_names_.size(); ++i)
      if (policy_names_[i] == name) return static_cast<int32_t>(i);
    policy_names_.push_back(name);
    return static_cast<int32_t>(policy_names_.size() - 1);
  }

  std::string task_, first_file_;
  int obs_dim_ = 0, act_dim_ = 0;
  std::vector<float> obs_, next_obs_, actions_, rewards_;
  std::vector<uint8_t> terminals_, timeouts_;
  std::vector<EpisodeInfo> episodes_;
  std::vector<std::string> policy_names_;
};

// The episodes of all files: messages vetted, put in order, complete episodes handed on.
class EpisodeAssembler {
 public:
  EpisodeAssembler(DatasetBuilder& builder, LogReadReport& report) : builder_(builder), report_(report) {}

  void take(const void* data, int size, const std::string& file) {
    masa::lcmt_transitions m;
    const transport::WireVerdict v = transport::decodeChecked(data, size, m);
    if (v != transport::WireVerdict::kOk) {
      reject(std::string("malformed message (") + std::string(transport::wireVerdictName(v)) + ")");
      return;
    }
    const std::string why = checkTransitions(m);
    if (!why.empty()) {
      reject("inconsistent message: " + why);
      return;
    }
    builder_.setShape(m, file);
    if (complete_.count(m.episode_id)) {
      reject("duplicate of a complete episode");
      return;
    }
    auto it = partial_.find(m.episode_id);
    if (it == partial_.end()) {
      if (m.step_offset != 0) {
        reject("episode without its start");
        return;
      }
      it = partial_.emplace(m.episode_id, PartialEpisode{}).first;
      it->second.policy_name = m.policy_name;
    }
    PartialEpisode& p = it->second;
    if (m.step_offset != p.next_offset || m.policy_name != p.policy_name) {
      reject("out-of-order or foreign message in an episode (the episode is dropped)");
      partial_.erase(it);
      return;
    }
    const size_t od = static_cast<size_t>(m.obs_dim);
    p.obs.insert(p.obs.end(), m.obs.begin(), m.obs.end() - static_cast<std::ptrdiff_t>(od));
    p.last_obs.assign(m.obs.end() - static_cast<std::ptrdiff_t>(od), m.obs.end());
    p.actions.insert(p.actions.end(), m.actions.begin(), m.actions.end());
    p.rewards.insert(p.rewards.end(), m.rewards.begin(), m.rewards.end());
    p.next_offset += m.num_steps;
    ++report_.messages;
    if (m.last) {
      builder_.add(m.episode_id, std::move(p), m.terminated, m.truncated, m.success);
      partial_.erase(it);
      complete_.insert(m.episode_id);
      ++report_.episodes;
      report_.transitions += m.step_offset + m.num_steps;
    }
  }

  void finish() {
    if (partial_.empty()) return;
    report_.rejected["incomplete episode (its last message never came)"] += static_cast<int64_t>(partial_.size());
    report_.notes.push_back(std::to_string(partial_.size()) +
                            " episode(s) without their last message were left out (a recording cut short?)");
  }

 private:
  void reject(const std::string& reason) { ++report_.rejected[reason]; }

  DatasetBuilder& builder_;
  LogReadReport& report_;
  std::unordered_map<int64_t, PartialEpisode> partial_;
  std::unordered_set<int64_t> complete_;
};

// Walks one log's events; a damaged or truncated tail ends the file with a note. Events go to the
// episodes only once the seal after them checks (log_seal.hpp); a log without any seal is read as
// lcm-logger recorded it, with a warning.
void readLogFile(const std::string& path, EpisodeAssembler& episodes, LogReadReport& report) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error("cannot open dataset log " + path + ": " + std::strerror(errno));
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(f, &std::fclose);
  std::error_code ec;
  const int64_t file_size = static_cast<int64_t>(std::filesystem::file_size(path, ec));
  int64_t pos = 0, events = 0, seals = 0;
  std::vector<unsigned char> buf;
  std::string channel;
  LogSealChain chain;
  std::vector<std::string> unsealed;  // the dataset's messages since the last seal
  auto stop = [&](const std::string& what) {
    report.notes.push_back(path + ": " + what + " at byte " + std::to_string(pos) + " after " +
                           std::to_string(events) + " event(s); the rest of the file is skipped");
    ++report.rejected["damaged or truncated log tail"];
  };
  for (;;) {
    unsigned char header[28];
    const size_t got = std::fread(header, 1, sizeof header, f);
    if (got == 0) break;  // the clean end
    if (got < sizeof header) {
      stop("truncated event header");
      break;
    }
    if (bigEndian(header, 4) != kLogSync) {
      if (events == 0) throw std::runtime_error(path + " is not an LCM log (no event marker at its start)");
      stop("no event marker (damaged)");
      break;
    }
    const int32_t channel_len = static_cast<int32_t>(bigEndian(header + 20, 4));
    const int32_t data_len = static_cast<int32_t>(bigEndian(header + 24, 4));
    const int64_t body = int64_t{channel_len} + data_len;
    if (channel_len <= 0 || channel_len > kMaxChannelBytes || data_len < 0 || data_len > kMaxEventBytes) {
      stop("impossible event lengths (damaged)");
      break;
    }
    if (file_size > 0 && pos + 28 + body > file_size) {
      stop("truncated event");
      break;
    }
    channel.resize(static_cast<size_t>(channel_len));
    buf.resize(static_cast<size_t>(data_len));
    if (std::fread(channel.data(), 1, channel.size(), f) != channel.size() ||
        std::fread(buf.data(), 1, buf.size(), f) != buf.size()) {
      stop("truncated event");
      break;
    }
    pos += 28 + body;
    ++events;
    ++report.events;
    const std::string_view data(reinterpret_cast<const char*>(buf.data()), buf.size());
    if (isSealEvent(channel, data)) {
      ++seals;
      if (chain.verify(data)) {
        for (const std::string& m : unsealed) episodes.take(m.data(), static_cast<int>(m.size()), path);
      } else if (!unsealed.empty()) {
        report.rejected["events whose seal fails (damaged log)"] += static_cast<int64_t>(unsealed.size());
        report.notes.push_back(path + ": the seal at byte " + std::to_string(pos - 28 - body) + " fails; the " +
                               std::to_string(unsealed.size()) + " event(s) it seals are left out");
      }
      unsealed.clear();
      continue;
    }
    chain.add(channel, data);
    if (channel != transport::kDatasetChannel) {
      ++report.other_channel;
      continue;
    }
    unsealed.emplace_back(data);
  }
  if (seals == 0) {
    ++report.unsealed_files;
    report.notes.push_back(path + ": no seal (lcm-logger's recording, or written before masa sealed its logs): events vetted, "
                                  "but nothing proves them intact");
    std::fprintf(stderr, "masa: warning: %s: an unsealed dataset log; nothing proves its events intact\n", path.c_str());
    for (const std::string& m : unsealed) episodes.take(m.data(), static_cast<int>(m.size()), path);
  } else if (!unsealed.empty()) {
    report.rejected["unsealed events after the last seal (a recording cut short)"] += static_cast<int64_t>(unsealed.size());
  }
}

}  // namespace

DatasetLogWriter::DatasetLogWriter(const std::string& path, int max_steps_per_message)
    : path_(path), max_steps_(max_steps_per_message), log_(std::make_unique<lcm::LogFile>(path, "w")) {
  if (!log_->good()) throw std::runtime_error("cannot create dataset log " + path);
  if (max_steps_ <= 0) throw std::invalid_argument("steps per message must be positive");
  writeSeal();  // the opening seal: this log is sealed, so a log without seals is not one of ours
}

void DatasetLogWriter::writeEvent(const char* channel, const unsigned char* data, int32_t size, int64_t utime) {
  lcm::LogEvent ev;
  ev.eventnum = 0;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = size;
  ev.data = const_cast<unsigned char*>(data);
  if (log_->writeEvent(&ev) != 0) throw std::runtime_error("writing " + path_ + " failed");
}

void DatasetLogWriter::writeSeal() {
  const std::string seal = seals_.seal();
  writeEvent(transport::kDatasetSealChannel, reinterpret_cast<const unsigned char*>(seal.data()), static_cast<int32_t>(seal.size()),
             transport::wallClockMicros());
  std::fflush(log_->getFilePtr());  // a crash loses at most the episode being written
}

DatasetLogWriter::~DatasetLogWriter() = default;

void DatasetLogWriter::write(const EpisodeRecord& episode) {
  std::vector<unsigned char> bytes;
  for (masa::lcmt_transitions& m : episodeMessages(episode, max_steps_, transport::wallClockMicros())) {
    bytes.resize(static_cast<size_t>(m.getEncodedSize()));
    m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    writeEvent(transport::kDatasetChannel, bytes.data(), static_cast<int32_t>(bytes.size()), m.utime);
    seals_.add(transport::kDatasetChannel, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  }
  writeSeal();
  ++episodes_;
}

int64_t LogReadReport::rejectedTotal() const {
  int64_t n = 0;
  for (const auto& [reason, count] : rejected) n += count;
  return n;
}

std::string LogReadReport::summary() const {
  std::ostringstream os;
  os << files << " log(s), " << events << " events: " << episodes << " episodes, " << transitions << " transitions";
  if (unsealed_files > 0) os << "; " << unsealed_files << " log(s) without seals";
  if (other_channel > 0) os << "; " << other_channel << " events of other channels ignored";
  os << "\n";
  for (const auto& [reason, count] : rejected) os << "  refused " << count << ": " << reason << "\n";
  for (const std::string& n : notes) os << "  note: " << n << "\n";
  return os.str();
}

TransitionDataset readDatasetLogs(const std::vector<std::string>& paths, LogReadReport* report_out) {
  if (paths.empty()) throw std::runtime_error("no dataset log given");
  LogReadReport report;
  DatasetBuilder builder;
  EpisodeAssembler episodes(builder, report);
  for (const std::string& p : paths) {
    readLogFile(p, episodes, report);
    ++report.files;
  }
  episodes.finish();
  if (report_out) *report_out = report;
  if (builder.empty())
    throw std::runtime_error("no complete episode on channel " + std::string(transport::kDatasetChannel) + " in " +
                             std::to_string(paths.size()) + " log(s): " + report.summary());
  return builder.finish();
}

std::vector<EpisodeRecord> datasetEpisodes(const TransitionDataset& d) {
  std::vector<EpisodeRecord> out;
  out.reserve(d.episodes.size());
  for (const EpisodeInfo& e : d.episodes) {
    EpisodeRecord r;
    r.task = d.task;
    r.episode_id = e.episode_id;
    r.policy_id = e.policy_id;
    r.policy_name = d.policy_names.at(static_cast<size_t>(e.policy_id));
    r.obs.resize(d.obs_dim, e.length + 1);
    r.obs.leftCols(e.length) = d.obs.middleCols(e.start, e.length);
    r.obs.col(e.length) = d.next_obs.col(e.start + e.length - 1);
    r.actions = d.actions.middleCols(e.start, e.length);
    r.rewards.assign(d.rewards.data() + e.start, d.rewards.data() + e.start + e.length);
    const int64_t last = e.start + e.length - 1;
    r.terminated = d.terminals[static_cast<size_t>(last)] != 0;
    r.truncated = d.timeouts[static_cast<size_t>(last)] != 0;
    r.success = e.success;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace masa::dataset
