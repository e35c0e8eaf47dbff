// The learner ranks of a data-parallel run, as the PPO update sees them: sums across ranks, every
// rank's value of a count, bytes from one rank to all, and a barrier that can be waited on while
// the rank goes on receiving rollouts.
//
// Every rank gets the same bits from sum() (the result of one reduction, not each rank's own
// order of additions), so ranks that start identical and apply the same steps stay identical; the
// parameter hash check (parameter_hash_check.hpp) verifies it. One rank (SoloCommunicator) is the
// plain learner: every call returns its input, and nothing else changes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace masa::cluster {

class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;

  // In place: x[i] becomes the sum over ranks of x[i].
  virtual void sum(double* x, int n) = 0;
  virtual void sum(float* x, int n) = 0;
  // Every rank's x, in rank order.
  virtual std::vector<int64_t> gather(int64_t x) = 0;
  // Rank `root`'s bytes to every rank (the others' vectors are resized to them).
  virtual void broadcast(std::vector<uint8_t>& bytes, int root) = 0;

  // A barrier in two halves: begin, then poll until every rank has begun. Between the two the
  // rank may do other work (drain its rollout intake), so waiting for a slow rank loses nothing.
  virtual void beginBarrier() = 0;
  virtual bool barrierDone() = 0;

  // "rank 1 of 2" (or "" for one rank): what messages and logs prefix.
  std::string describe() const;
};

// A single learner: sums of one, its own value, its own bytes.
class SoloCommunicator final : public Communicator {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void sum(double*, int) override {}
  void sum(float*, int) override {}
  std::vector<int64_t> gather(int64_t x) override { return {x}; }
  void broadcast(std::vector<uint8_t>&, int) override {}
  void beginBarrier() override {}
  bool barrierDone() override { return true; }
};

// The process's single-rank communicator, for code that takes one by reference by default.
Communicator& soloCommunicator();

}  // namespace masa::cluster
