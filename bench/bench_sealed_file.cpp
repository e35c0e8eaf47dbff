// What writing a learner's state costs (issue #34: an off-policy run's checkpoints, replay included,
// took 44% of its wall time): a payload of N MiB, written through a std::ostream in 4 MiB pieces,
// sealed and flushed to the disk (fsync) in the run directory's file system.
//   Streamed: writeSealedFileStreamed, the payload hashed and written as it comes (the learner now);
//   Copied:   the learner before, the payload built in an ostringstream, copied out (str()), sealed
//             in memory (sealBytes) and written.
// Learner::writeOffPolicyState writes 686 MB at 1M transitions of Humanoid Tightrope.
//   build/bench/bench_sealed_file            (writes under $TMPDIR or /tmp)
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "common/integrity/sealed_file.hpp"

namespace {

using namespace masa::integrity;
namespace fs = std::filesystem;

constexpr FileKind kStateKind{"masa bench state", "BENCHST1"};
constexpr std::size_t kPiece = std::size_t{4} << 20;

std::string benchPath() { return (fs::temp_directory_path() / ("masa_bench_sealed_" + std::to_string(::getpid()) + ".bin")).string(); }

void writePayload(std::ostream& os, const std::vector<char>& piece, std::size_t mib) {
  for (std::size_t done = 0; done < (mib << 20); done += piece.size()) os.write(piece.data(), static_cast<std::streamsize>(piece.size()));
}

std::vector<char> somePiece() {
  std::vector<char> piece(kPiece);
  for (std::size_t i = 0; i < piece.size(); ++i) piece[i] = static_cast<char>(i * 2654435761u >> 13);
  return piece;
}

void Streamed(benchmark::State& state) {
  const auto mib = static_cast<std::size_t>(state.range(0));
  const auto piece = somePiece();
  const std::string path = benchPath();
  for (auto _ : state) writeSealedFileStreamed(path, kStateKind, [&](std::ostream& os) { writePayload(os, piece, mib); });
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * (mib << 20)));
  fs::remove(path);
}

void Copied(benchmark::State& state) {
  const auto mib = static_cast<std::size_t>(state.range(0));
  const auto piece = somePiece();
  const std::string path = benchPath(), tmp = path + ".tmp";
  for (auto _ : state) {
    std::ostringstream os;
    writePayload(os, piece, mib);
    const std::string sealed = sealBytes(kStateKind, os.str());
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f || std::fwrite(sealed.data(), 1, sealed.size(), f) != sealed.size() || std::fflush(f) != 0 || ::fsync(fileno(f)) != 0) {
      state.SkipWithError("write failed");
      break;
    }
    std::fclose(f);
    fs::rename(tmp, path);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * (mib << 20)));
  fs::remove(path);
}

BENCHMARK(Streamed)->Arg(64)->Arg(686)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(Copied)->Arg(64)->Arg(686)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
