// shellQuoted: what /bin/sh receives is the one word given, whatever it holds.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "common/core/shell_quoted.hpp"

namespace {

// The shell's own reading of `printf %s WORD`, as the tools' popen/system would run it.
std::string echoedByShell(const std::string& word) {
  const std::string cmd = "printf '%s|' " + masa::shellQuoted(word);
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return "<no shell>";
  std::string out;
  char buf[256];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

TEST(ShellQuoted, TheShellReceivesExactlyTheOneWordGiven) {
  for (const std::string word : {"plain.mp4", "with space.mp4", "quote'in'side.mp4", "'", "''", "$(touch x)",
                                 "`id`", "a;b|c&d>e<f", "back\\slash", "new\nline", "*.png", "-dash", ""})
    EXPECT_EQ(echoedByShell(word), word + "|") << "word: " << word;
}

TEST(ShellQuoted, QuotesAreClosedEscapedAndReopened) {
  EXPECT_EQ(masa::shellQuoted("a'b"), "'a'\\''b'");
  EXPECT_EQ(masa::shellQuoted(""), "''");
}

}  // namespace
