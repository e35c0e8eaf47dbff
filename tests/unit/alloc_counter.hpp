// Process-wide count of heap allocations, for tests that assert a hot loop allocates nothing.
// alloc_counter.cpp interposes malloc and friends (forwarding to glibc's own entry points);
// operator new alone would miss Eigen, which allocates with malloc.
#pragma once

namespace masa::test {

// False under a sanitizer, which owns malloc: tests should then skip.
bool allocationCountingEnabled();
// Allocations so far (0 when counting is disabled).
long allocationCount();

}  // namespace masa::test
