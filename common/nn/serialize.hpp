// Save and load a ParameterSet: a small binary format with a magic, the scalar type, and every
// segment's name and shape, so that loading into a differently-shaped model fails with a message
// naming the first segment that differs. Values round-trip bit for bit.
#pragma once

#include <iosfwd>
#include <string>

#include "common/nn/parameter_set.hpp"

namespace masa::nn {

template <typename S>
void saveParameters(const ParameterSet<S>& params, std::ostream& os);
template <typename S>
void loadParameters(ParameterSet<S>& params, std::istream& is, const std::string& source_name = "<stream>");

template <typename S>
void saveParameters(const ParameterSet<S>& params, const std::string& path);
template <typename S>
void loadParameters(ParameterSet<S>& params, const std::string& path);

}  // namespace masa::nn
