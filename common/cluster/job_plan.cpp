#include "common/cluster/job_plan.hpp"

#include <cstring>
#include <stdexcept>

namespace masa::cluster {

namespace {
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'P', 'L', 'N', '1'};
}

std::vector<uint8_t> JobPlan::encode() const {
  std::vector<uint8_t> out(kMagic, kMagic + sizeof kMagic);
  // resize + memcpy rather than insert(end, b, b + n): GCC 12 at -O3 reports a false -Warray-bounds
  // inside vector::insert for the 8-byte fields.
  auto put = [&](const void* p, std::size_t n) {
    const std::size_t at = out.size();
    out.resize(at + n);
    if (n > 0) std::memcpy(out.data() + at, p, n);
  };
  put(&run_id, sizeof run_id);
  const uint32_t url_size = static_cast<uint32_t>(url.size());
  put(&url_size, sizeof url_size);
  put(url.data(), url.size());
  if (key && signed_job) throw std::logic_error("job plan: a run key and a signed job exclude each other");
  // The authentication byte: 0 none, 1 the run key follows, 2 signed.
  const uint8_t auth = signed_job ? 2 : key ? 1 : 0;
  put(&auth, 1);
  if (key) put(key->data(), key->size());
  return out;
}

JobPlan JobPlan::decode(const std::vector<uint8_t>& bytes) {
  std::size_t at = 0;
  auto take = [&](void* p, std::size_t n) {
    if (bytes.size() - at < n) throw std::runtime_error("job plan from learner rank 0 is truncated");
    std::memcpy(p, bytes.data() + at, n);
    at += n;
  };
  char magic[sizeof kMagic];
  take(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof magic) != 0) throw std::runtime_error("job plan from learner rank 0: bad magic");
  JobPlan plan;
  take(&plan.run_id, sizeof plan.run_id);
  uint32_t url_size = 0;
  take(&url_size, sizeof url_size);
  if (url_size > 4096) throw std::runtime_error("job plan from learner rank 0: URL of " + std::to_string(url_size) + " bytes");
  plan.url.resize(url_size);
  take(plan.url.data(), url_size);
  uint8_t auth = 0;
  take(&auth, 1);
  if (auth > 2) throw std::runtime_error("job plan from learner rank 0: bad authentication byte " + std::to_string(auth));
  plan.signed_job = auth == 2;
  if (auth == 1) {
    plan.key.emplace();
    take(plan.key->data(), plan.key->size());
  }
  if (at != bytes.size()) throw std::runtime_error("job plan from learner rank 0 has trailing bytes");
  return plan;
}

}  // namespace masa::cluster
