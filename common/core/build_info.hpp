#pragma once
// Which code made a run: the commit these binaries were built from, as `git describe --always
// --dirty` of the source tree printed it at build time ("-dirty" with uncommitted changes, "unknown"
// outside a checkout). Every tool answers --version with it and every run's config.yaml names it.

namespace masa {

const char* buildCommit();

}  // namespace masa
