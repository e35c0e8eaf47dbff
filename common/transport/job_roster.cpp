#include "common/transport/job_roster.hpp"

#include <memory>
#include <stdexcept>
#include <string>

namespace masa::transport {

namespace {
const char* const kSource = "of the MPI job (gathered over MPI)";

// Who in a job may publish what: the lead learner rank and the actors; nothing for the other ranks.
bool listed(SenderId id) { return id.role == Role::kActor || (id.role == Role::kLearner && id.index == 0); }
}  // namespace

std::vector<uint8_t> jobKeyRecord(SenderId id, const integrity::PublicKeyBytes& key) {
  std::vector<uint8_t> r;
  r.reserve(kJobKeyRecordBytes);
  r.push_back(static_cast<uint8_t>(id.role));
  for (int shift = 24; shift >= 0; shift -= 8) r.push_back(static_cast<uint8_t>(id.index >> shift));
  r.insert(r.end(), key.begin(), key.end());
  return r;
}

Roster jobRoster(const std::vector<uint8_t>& records) {
  if (records.empty() || records.size() % kJobKeyRecordBytes != 0)
    throw std::runtime_error(std::string("roster ") + kSource + ": " + std::to_string(records.size()) +
                             " bytes are not whole records of " + std::to_string(kJobKeyRecordBytes));
  Roster roster(kSource);
  for (std::size_t at = 0; at < records.size(); at += kJobKeyRecordBytes) {
    const uint8_t* r = records.data() + at;
    const std::string which = "process " + std::to_string(at / kJobKeyRecordBytes);
    if (!isRole(r[0]) || (r[0] != static_cast<uint8_t>(Role::kLearner) && r[0] != static_cast<uint8_t>(Role::kActor)))
      throw std::runtime_error(std::string("roster ") + kSource + ": " + which + " has role byte " +
                               std::to_string(r[0]) + ", neither learner nor actor");
    SenderId id;
    id.role = static_cast<Role>(r[0]);
    id.index = (uint32_t{r[1]} << 24) | (uint32_t{r[2]} << 16) | (uint32_t{r[3]} << 8) | r[4];
    if (!listed(id)) continue;
    integrity::PublicKeyBytes key{};
    std::copy(r + 5, r + kJobKeyRecordBytes, key.begin());
    try {
      roster.add(id, key, defaultChannels(id.role));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("roster ") + kSource + ": " + which + ": " + e.what());
    }
  }
  return roster;
}

SignedMode jobSignedMode(SenderId me, const GatherAll& gather_all) {
  integrity::SigningKey key = integrity::SigningKey::generate();
  auto roster = std::make_shared<Roster>(jobRoster(gather_all(jobKeyRecord(me, key.publicKey()))));
  SignedMode mode;
  if (listed(me)) {
    const Roster::Entry* entry = roster->find(me);
    // Another process of the job said it is this one: the roster would believe its key, not ours.
    if (entry == nullptr || entry->key != key.publicKey())
      throw std::runtime_error("roster " + std::string(kSource) + " gives " + me.name() + " another key than its own");
    mode.signer = std::make_shared<MessageSigner>(std::move(key), me);
  }
  mode.roster = std::move(roster);
  return mode;
}

}  // namespace masa::transport
