#include "common/cluster/communicator.hpp"

namespace masa::cluster {

std::string Communicator::describe() const {
  return size() == 1 ? std::string() : "rank " + std::to_string(rank()) + " of " + std::to_string(size());
}

Communicator& soloCommunicator() {
  static SoloCommunicator solo;
  return solo;
}

}  // namespace masa::cluster
