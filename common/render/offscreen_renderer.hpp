// Renders a MuJoCo scene offscreen into RGB frames (needs an OpenGL context: a display, or Xvfb:
// `xvfb-run -a <command>`), and streams them to ffmpeg as a video (.mp4, .gif) or an image strip
// (.png: frames tiled side by side).
#pragma once

#include <mujoco/mujoco.h>

#include <cstdio>
#include <string>
#include <vector>

namespace masa::render {

class OffscreenRenderer {
 public:
  // Throws std::runtime_error with what to do when no GL context can be made.
  OffscreenRenderer(const mjModel* model, int width, int height);
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  // A camera following `body` (e.g. the torso) from a three-quarter view.
  void trackBody(int body, double distance, double azimuth_deg, double elevation_deg);
  // Renders the current state, with an optional text label in the top left corner; returns
  // width*height*3 bytes, top row first.
  const std::vector<unsigned char>& render(const mjData* data, const std::string& label = "");
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  const mjModel* model_;
  int width_, height_;
  void* window_ = nullptr;
  mjvScene scene_;
  mjvCamera camera_;
  int track_body_ = -1;
  mjvOption option_;
  mjrContext context_;
  std::vector<unsigned char> rgb_, flipped_;
};

// The body a camera should follow: of the bodies with a free joint, the one with the most
// descendants (a floating robot's trunk, not a ball or a pole it plays with), else body 1.
int rootBody(const mjModel* model);
// A camera distance that frames the robot (its root body's subtree, as posed in `data`), not the
// whole scene (a 50 m beam).
double robotViewDistance(const mjModel* model, const mjData* data);

// A .png output is an image strip (frames tiled side by side); anything else is a video.
bool isStripPath(const std::string& path);

// Pipes raw RGB frames into ffmpeg. The output kind follows the file extension.
class FrameWriter {
 public:
  FrameWriter(const std::string& path, int width, int height, double fps, int strip_frames = 8);
  ~FrameWriter();  // closes the pipe: ffmpeg writes the file
  void write(const std::vector<unsigned char>& rgb);
  bool isStrip() const { return strip_; }
  int stripFrames() const { return strip_frames_; }

 private:
  std::FILE* pipe_ = nullptr;
  std::string path_;
  bool strip_;
  int strip_frames_;
};

}  // namespace masa::render
