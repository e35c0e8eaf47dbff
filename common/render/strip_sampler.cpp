#include "common/render/strip_sampler.hpp"

#include <cmath>
#include <stdexcept>

#include "common/render/offscreen_renderer.hpp"

namespace masa::render {

StripSampler::StripSampler(int frames) : frames_(frames) {
  if (frames < 1) throw std::invalid_argument("a strip needs at least one frame");
}

void StripSampler::add(int step, Image image) {
  kept_.emplace_back(step, std::move(image));
  if (static_cast<int>(kept_.size()) < 2 * frames_) return;
  stride_ *= 2;
  std::vector<std::pair<int, Image>> thinned;
  for (auto& k : kept_)
    if (k.first % stride_ == 0) thinned.push_back(std::move(k));
  kept_.swap(thinned);
}

void StripSampler::addLast(int step, Image image) {
  if (!kept_.empty() && kept_.back().first == step) return;
  kept_.emplace_back(step, std::move(image));
}

std::vector<size_t> StripSampler::pickIndices() const {
  const size_t n = kept_.size(), f = std::min(n, static_cast<size_t>(frames_));
  std::vector<size_t> idx;
  if (f == 1) {
    idx.push_back(n - 1);
    return idx;
  }
  // Evenly over the kept steps (themselves evenly spaced but for the last): first and last included.
  for (size_t i = 0; i < f; ++i) idx.push_back(static_cast<size_t>(std::lround(double(i) * double(n - 1) / double(f - 1))));
  return idx;
}

std::vector<const StripSampler::Image*> StripSampler::pick() const {
  std::vector<const Image*> out;
  for (size_t i : pickIndices()) out.push_back(&kept_[i].second);
  return out;
}

int StripSampler::writeStrip(const std::string& path, int width, int height) const {
  const auto picked = pick();
  FrameWriter writer(path, width, height, /*fps=*/1.0, static_cast<int>(picked.size()));
  for (const Image* image : picked) writer.write(*image);
  return static_cast<int>(picked.size());
}

std::vector<int> StripSampler::pickedSteps() const {
  std::vector<int> out;
  for (size_t i : pickIndices()) out.push_back(kept_[i].first);
  return out;
}

}  // namespace masa::render
