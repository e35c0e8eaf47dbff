// The rollout chunk on the wire (lcmt_rollout_chunk), as one table: the length each of its length
// fields must hold given the chunk's shape. The actor's chunker computes its byte budget from it
// (with the field table of common/transport/wire_layout.hpp), and the learner's validator checks
// every arriving chunk against it, so the two cannot disagree about what a chunk is.
// tests/unit/test_chunk_layout.cpp checks that every length field of the wire table has a rule here.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "common/transport/wire_layout.hpp"

namespace masa::rollout {

// What fixes the length of each array of a chunk.
struct ChunkShape {
  int64_t horizon = 0;
  int64_t num_envs = 0;
  int64_t obs_dim = 0;
  int64_t act_dim = 0;
  int64_t num_final = 0;     // truncated steps in the chunk
  int64_t num_episodes = 0;  // episodes that ended in it
  int64_t num_terms = 0;     // reward terms of the task
};

struct ChunkLengthRule {
  std::string_view field;  // a length field of lcmt_rollout_chunk
  int64_t (*length)(const ChunkShape&);
};

// lcmt_rollout_chunk.lcm's comments, as code.
inline constexpr ChunkLengthRule kChunkLengthRules[] = {
    {"obs_len", [](const ChunkShape& s) { return (s.horizon + 1) * s.num_envs * s.obs_dim; }},
    {"act_len", [](const ChunkShape& s) { return s.horizon * s.num_envs * s.act_dim; }},
    {"step_len", [](const ChunkShape& s) { return s.horizon * s.num_envs; }},
    {"log_std_len", [](const ChunkShape& s) { return s.act_dim; }},
    {"num_final", [](const ChunkShape& s) { return s.num_final; }},
    {"final_obs_len", [](const ChunkShape& s) { return s.num_final * s.obs_dim; }},
    {"num_episodes", [](const ChunkShape& s) { return s.num_episodes; }},
    {"num_terms", [](const ChunkShape& s) { return s.num_terms; }},
    {"term_sums_len", [](const ChunkShape& s) { return s.num_episodes * s.num_terms; }},
};

// The length `field` must hold in a chunk of this shape; throws std::logic_error for a field
// without a rule (a programming error: the table above is out of date).
inline int64_t chunkLength(std::string_view field, const ChunkShape& shape) {
  for (const ChunkLengthRule& r : kChunkLengthRules) {
    if (r.field == field) return r.length(shape);
  }
  throw std::logic_error("chunk_layout: no length rule for lcmt_rollout_chunk field '" + std::string(field) + "'");
}

// Encoded bytes of a chunk of this shape: the 8-byte type hash, then every field of the wire
// table at its length. Strings are an int32 length and their bytes with a NUL: `term_name_bytes`
// is the sum of the term names' sizes (without NULs).
inline int64_t chunkEncodedBytes(const ChunkShape& shape, int64_t term_name_bytes) {
  using transport::WireType;
  auto size = [](WireType t) -> int64_t {
    switch (t) {
      case WireType::kInt8: case WireType::kByte: case WireType::kBoolean: return 1;
      case WireType::kInt16: return 2;
      case WireType::kInt32: case WireType::kFloat: return 4;
      case WireType::kInt64: case WireType::kDouble: return 8;
      case WireType::kString: return 5;  // an empty string: length and NUL
    }
    return 0;
  };
  int64_t bytes = 8;
  for (const transport::WireField& f : transport::WireLayoutOf<masa::lcmt_rollout_chunk>::fields) {
    const int64_t count = f.length.empty() ? 1 : chunkLength(f.length, shape);
    bytes += count * size(f.type);
    if (f.type == WireType::kString && !f.length.empty()) bytes += term_name_bytes;  // term_names
  }
  return bytes;
}

}  // namespace masa::rollout
