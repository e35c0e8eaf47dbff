// Picks the frames of an image strip in one pass over an episode of unknown length: it keeps
// every stride-th step, and when it holds twice the frames wanted it drops every other one and
// doubles the stride. At the end, `frames` of what it kept (always including the first and the
// last step) are spread evenly over the episode, however short: a 10-step episode gives a full
// strip of distinct frames, not one frame and black tiles. Holds at most 2 x frames + 1 images.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace masa::render {

class StripSampler {
 public:
  using Image = std::vector<unsigned char>;
  explicit StripSampler(int frames);

  // Whether the frame of `step` should be rendered and add()ed (steps count from 0).
  bool wants(int step) const { return step % stride_ == 0; }
  void add(int step, Image image);
  // The episode's last step (rendered whether or not wants() asked for it).
  void addLast(int step, Image image);
  // min(frames, steps kept) images, evenly spread, in step order.
  std::vector<const Image*> pick() const;
  std::vector<int> pickedSteps() const;
  // Writes the picked images as a .png strip of width x height frames; returns how many.
  int writeStrip(const std::string& path, int width, int height) const;

 private:
  std::vector<std::size_t> pickIndices() const;
  int frames_;
  int stride_ = 1;
  std::vector<std::pair<int, Image>> kept_;
};

}  // namespace masa::render
