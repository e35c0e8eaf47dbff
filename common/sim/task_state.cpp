// A task's full state as numbers: copies between instances (the symmetry verifier's) and saved
// actors (masa_train's checkpoints) go through the same layout, so neither can miss a part.
//
// Layout: a header of sizes (checked on load), then the simulator's state, the last action, the
// episode so far, the last step's reward terms, and the task's extras with their count.
#include <algorithm>
#include <stdexcept>
#include <string>

#include "common/core/check.hpp"
#include "common/sim/task.hpp"

namespace masa::task {
namespace {

constexpr double kStateTag = 20261201.0;  // the layout's version; a different one is refused

// Reads in order, and says which part was missing or of the wrong size.
class StateReader {
 public:
  StateReader(std::span<const double> in, const std::string& task) : in_(in), task_(task) {}
  std::span<const double> take(std::size_t n, const char* what) {
    if (n > in_.size() - at_)
      throw std::runtime_error("task state of " + task_ + ": " + what + " is cut short (" +
                               std::to_string(in_.size() - at_) + " values left, " + std::to_string(n) + " needed)");
    const auto part = in_.subspan(at_, n);
    at_ += n;
    return part;
  }
  double one(const char* what) { return take(1, what)[0]; }
  void into(double* dst, std::size_t n, const char* what) {
    const auto part = take(n, what);
    std::copy(part.begin(), part.end(), dst);
  }
  void expect(double want, const char* what) {
    const double have = one(what);
    if (have != want)
      throw std::runtime_error("task state of " + task_ + ": " + what + " is " + std::to_string(have) + ", this " +
                               task_ + " has " + std::to_string(want));
  }
  std::size_t left() const { return in_.size() - at_; }

 private:
  std::span<const double> in_;
  std::size_t at_ = 0;
  const std::string& task_;
};

}  // namespace

void Task::saveState(std::vector<double>& out) const {
  const mjModel* m = model_->get();
  const int nterms = static_cast<int>(term_names_.size());
  auto put = [&](const double* p, std::size_t n) { out.insert(out.end(), p, p + n); };
  out.insert(out.end(), {kStateTag, double(m->nq), double(m->nv), double(m->na), double(m->nu), double(m->nbody),
                         double(m->nmocap), double(m->nuserdata), double(actDim()), double(nterms)});
  out.push_back(data_->time);
  put(data_->qpos, m->nq);
  put(data_->qvel, m->nv);
  put(data_->act, m->na);
  put(data_->ctrl, m->nu);
  put(data_->qacc_warmstart, m->nv);
  put(data_->qfrc_applied, m->nv);
  put(data_->xfrc_applied, 6 * m->nbody);
  put(data_->mocap_pos, 3 * m->nmocap);
  put(data_->mocap_quat, 4 * m->nmocap);
  put(data_->userdata, m->nuserdata);
  put(last_action_.data(), last_action_.size());
  out.insert(out.end(), {episode_.ret, double(episode_.length), double(episode_.has_success), double(episode_.success),
                         double(episode_.terminated), double(episode_.truncated)});
  put(episode_.term_sums.data(), episode_.term_sums.size());
  put(terms_.data(), terms_.size());
  if (randomization_) {  // the episode's physics, noise seed and delayed actions (only then: old states keep their layout)
    const std::size_t at = out.size();
    out.push_back(0.0);
    randomization_->save(out);
    out.push_back(noise_seed_);
    out.push_back(static_cast<double>(commanded_.size()));
    for (const auto& c : commanded_) put(c.data(), c.size());
    out[at] = static_cast<double>(out.size() - at - 1);
  }
  const std::size_t count_at = out.size();
  out.push_back(0.0);
  saveExtras(out);
  out[count_at] = static_cast<double>(out.size() - count_at - 1);
}

void Task::loadState(std::span<const double> in) {
  const mjModel* m = model_->get();
  const int nterms = static_cast<int>(term_names_.size());
  StateReader r(in, name_);
  r.expect(kStateTag, "the layout version");
  r.expect(m->nq, "nq");
  r.expect(m->nv, "nv");
  r.expect(m->na, "na");
  r.expect(m->nu, "nu");
  r.expect(m->nbody, "nbody");
  r.expect(m->nmocap, "nmocap");
  r.expect(m->nuserdata, "nuserdata");
  r.expect(actDim(), "the action size");
  r.expect(nterms, "the number of reward terms");
  data_->time = r.one("time");
  r.into(data_->qpos, m->nq, "qpos");
  r.into(data_->qvel, m->nv, "qvel");
  r.into(data_->act, m->na, "act");
  r.into(data_->ctrl, m->nu, "ctrl");
  r.into(data_->qacc_warmstart, m->nv, "qacc_warmstart");
  r.into(data_->qfrc_applied, m->nv, "qfrc_applied");
  r.into(data_->xfrc_applied, 6 * m->nbody, "xfrc_applied");
  r.into(data_->mocap_pos, 3 * m->nmocap, "mocap_pos");
  r.into(data_->mocap_quat, 4 * m->nmocap, "mocap_quat");
  r.into(data_->userdata, m->nuserdata, "userdata");
  r.into(last_action_.data(), last_action_.size(), "the last action");
  episode_.ret = r.one("the episode's return");
  episode_.length = static_cast<int>(r.one("the episode's length"));
  episode_.has_success = r.one("the episode's flags") != 0.0;
  episode_.success = r.one("the episode's flags") != 0.0;
  episode_.terminated = r.one("the episode's flags") != 0.0;
  episode_.truncated = r.one("the episode's flags") != 0.0;
  r.into(episode_.term_sums.data(), episode_.term_sums.size(), "the episode's reward terms");
  r.into(terms_.data(), terms_.size(), "the last step's reward terms");
  if (randomization_) {
    const double n = r.one("the count of the randomized physics");
    if (!(n >= 0.0 && n <= static_cast<double>(r.left())))
      throw std::runtime_error("task state of " + name_ + ": the randomized physics says " + std::to_string(n) + " values");
    const std::span<const double> block = r.take(static_cast<std::size_t>(n), "the randomized physics");
    std::size_t at = randomization_->load(block, name_);
    randomization_->summarize(episode_.physics);  // the episode statistics' record of the draws
    if (block.size() < at + 2) throw std::runtime_error("task state of " + name_ + ": the randomized physics is cut short");
    noise_seed_ = block[at++];
    const double steps = block[at++];
    if (!(steps >= 2.0 && steps == static_cast<double>(randomization_->latencySteps() + 2) &&
          block.size() == at + static_cast<std::size_t>(steps) * actDim()))
      throw std::runtime_error("task state of " + name_ + ": the delayed actions do not match the latency");
    commanded_.assign(static_cast<std::size_t>(steps), std::vector<double>(actDim(), 0.0));
    for (auto& c : commanded_) {
      std::copy(block.begin() + static_cast<std::ptrdiff_t>(at), block.begin() + static_cast<std::ptrdiff_t>(at + actDim()), c.begin());
      at += actDim();
    }
  }
  const double count = r.one("the count of the task's extras");
  if (!(count >= 0.0 && count == static_cast<double>(r.left())))
    throw std::runtime_error("task state of " + name_ + ": " + std::to_string(r.left()) +
                             " values after the count of the task's extras, which says " + std::to_string(count));
  loadExtras(r.take(r.left(), "the task's extras"));
  forwardKeepingState();
}

void Task::copyStateFrom(const Task& other) {
  MASA_CHECK(other.name_ == name_ && other.model()->nq == model()->nq, "copyStateFrom needs the same task");
  std::vector<double> state;
  other.saveState(state);
  loadState(state);
}

}  // namespace masa::task
