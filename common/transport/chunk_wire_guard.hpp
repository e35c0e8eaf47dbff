// A bounds check of an encoded lcmt_rollout_chunk BEFORE it is decoded.
//
// lcm-gen's C++ decoder resizes each array to its length field before checking that the bytes
// are there, so one hostile length (2^31 - 1 floats) makes the learner allocate 8 GB. This walk
// reads only the length fields, at their positions in the wire format, and accepts the buffer only
// if every array fits in it and the message ends exactly at its end. It must follow the field order
// of lcmtypes/lcmt_rollout_chunk.lcm; a unit test compares it with the generated encoder.
#pragma once

namespace masa::transport {

// True when `data` (size bytes) carries lcmt_rollout_chunk's hash and lengths that fit exactly.
bool chunkWireLengthsFit(const void* data, int size);

}  // namespace masa::transport
