// The four ways of structuring policy and critic that the paper compares.
#pragma once

#include <string>

namespace masa::model {

enum class Method {
  kMasa,  // shared nets on T_i(o), equivariant policy, invariant critic
  kSa,    // one net on o for the whole robot
  kSasa,  // SA plus symmetry losses on the orbit of o
  kMa,    // shared nets on [o, one-hot(i)] without transforms
};

Method parseMethod(const std::string& name);  // "masa" | "sa" | "sasa" | "ma" (case-insensitive)
std::string methodName(Method m);

}  // namespace masa::model
