#include "common/core/build_info.hpp"

#include "masa/git_commit.hpp"  // generated at every build (cmake/git_commit.cmake); only this file includes it

namespace masa {

const char* buildCommit() { return MASA_GIT_COMMIT; }

}  // namespace masa
