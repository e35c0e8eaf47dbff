#pragma once
// One word for /bin/sh: the tools start ffmpeg and gnuplot through a shell (popen, system), and a
// path or name a user chose ("run's dir", "a$(rm -rf ~)") must reach them as the same single
// argument, never as shell syntax.

#include <string>
#include <string_view>

namespace masa {

// `s` inside single quotes, each ' written as '\'' (close, an escaped quote, reopen): POSIX sh
// gives every other character inside single quotes its literal value.
std::string shellQuoted(std::string_view s);

}  // namespace masa
