// Files whose bytes decide whom a process believes: a run's roster, a private signing key. Anyone
// who can write such a file, or replace it, picks the keys that are believed (issue #55, item 4).
// So one is read only when
//   - it is a regular file owned by the user running masa (or by root),
//   - nobody else may write it (a secret one: nobody else may read it either),
//   - its directory is owned by that user (or root) and nobody else may write it (else another user
//     renames our file away and puts theirs in its place, as ssh's StrictModes refuses),
// and the bytes read are those of the file checked: it is opened once and the checks run on the
// open descriptor (fstat), so nothing can be swapped in between the check and the read.
#pragma once

#include <string>

namespace masa::integrity {

enum class FileSecrecy { kPublic, kSecret };

// The file's bytes; throws std::runtime_error "<what> <path>: <reason> (<how to fix it>)" when a
// check fails or the file cannot be read. `what` names the file's role ("roster", "private key").
std::string readOwnedFile(const std::string& path, const std::string& what, FileSecrecy secrecy);

}  // namespace masa::integrity
