// metrics.csv on resume: the learner appends one row per update, but writes a checkpoint only every
// runner.checkpoint_every updates, so a learner killed between two checkpoints leaves rows for
// updates that a resume from the last checkpoint does again. Cutting the file back to the
// checkpoint first keeps one row per update, in order.
#pragma once

#include <cstdint>
#include <string>

namespace masa::learner {

// Keeps the header line and the rows whose update number (the first column, `update`, from 1) is
// at most `updates`, the checkpoint's update count, with as many columns as the header; drops the
// rest (a row torn by the kill among them). A file of a run made before updates had one name
// (columns `epoch,version,...`, epoch from 0 and version = epoch + 1) is rewritten in today's form
// first: its `epoch` column goes and `version` is the update, so the resumed run's rows match.
// Rewrites the file atomically (a temporary beside it, renamed). A missing file stays missing.
// Returns the number of lines removed. Throws std::runtime_error when the file cannot be rewritten.
int64_t truncateMetricsCsv(const std::string& path, int64_t updates);

}  // namespace masa::learner
