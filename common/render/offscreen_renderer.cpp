#include "common/render/offscreen_renderer.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "common/core/shell_quoted.hpp"

namespace masa::render {

OffscreenRenderer::OffscreenRenderer(const mjModel* model, int width, int height) : model_(model) {
  if (!glfwInit())
    throw std::runtime_error(
        "cannot initialise GLFW for offscreen rendering (no display?): run the command under `xvfb-run -a`");
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  GLFWwindow* w = glfwCreateWindow(64, 64, "masa", nullptr, nullptr);
  if (!w) {
    glfwTerminate();
    throw std::runtime_error("cannot create an OpenGL context: run the command under `xvfb-run -a`");
  }
  window_ = w;
  glfwMakeContextCurrent(w);
  mjv_defaultScene(&scene_);
  mjv_defaultCamera(&camera_);
  mjv_defaultOption(&option_);
  mjr_defaultContext(&context_);
  mjv_makeScene(model, &scene_, 4000);
  mjr_makeContext(model, &context_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  // The offscreen buffer's size is set by the model (visual/global offwidth, offheight).
  width_ = std::min(width, context_.offWidth);
  height_ = std::min(height, context_.offHeight);
  rgb_.resize(static_cast<size_t>(width_) * height_ * 3);
  flipped_.resize(rgb_.size());
}

OffscreenRenderer::~OffscreenRenderer() {
  mjr_freeContext(&context_);
  mjv_freeScene(&scene_);
  glfwDestroyWindow(static_cast<GLFWwindow*>(window_));
  glfwTerminate();
}

void OffscreenRenderer::trackBody(int body, double distance, double azimuth_deg, double elevation_deg) {
  // A free camera re-aimed at the body on every frame: MuJoCo's tracking camera eases towards its
  // body a little per render, so sparse frames (a strip) would lose the robot.
  camera_.type = mjCAMERA_FREE;
  track_body_ = body;
  camera_.distance = distance;
  camera_.azimuth = azimuth_deg;
  camera_.elevation = elevation_deg;
}

const std::vector<unsigned char>& OffscreenRenderer::render(const mjData* data, const std::string& label) {
  mjrRect viewport{0, 0, width_, height_};
  if (track_body_ >= 0)
    for (int k = 0; k < 3; ++k) camera_.lookat[k] = data->xpos[3 * track_body_ + k];
  mjv_updateScene(model_, const_cast<mjData*>(data), &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  mjr_render(viewport, &scene_, &context_);
  if (!label.empty()) mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport, label.c_str(), nullptr, &context_);
  mjr_readPixels(rgb_.data(), nullptr, viewport, &context_);
  // OpenGL rows start at the bottom.
  const size_t row = static_cast<size_t>(width_) * 3;
  for (int y = 0; y < height_; ++y)
    std::memcpy(flipped_.data() + y * row, rgb_.data() + (height_ - 1 - y) * row, row);
  return flipped_;
}

double robotViewDistance(const mjModel* model, const mjData* data) {
  const int root = rootBody(model);
  double radius = 0.0;
  for (int b = root + 1; b < model->nbody; ++b) {
    int up = b;
    while (up > root) up = model->body_parentid[up];
    if (up != root) continue;  // not in the root's subtree
    double d = 0.0;
    for (int k = 0; k < 3; ++k) d += (data->xpos[3 * b + k] - data->xpos[3 * root + k]) * (data->xpos[3 * b + k] - data->xpos[3 * root + k]);
    radius = std::max(radius, std::sqrt(d));
  }
  if (radius <= 0.0) return std::min(3.0, 1.5 * model->stat.extent);
  return std::clamp(4.0 * radius, 0.6, std::min(4.0, 1.5 * model->stat.extent));
}

int rootBody(const mjModel* model) {
  // The robot, not a ball or a pole: of the bodies with a free joint, the one with most descendants.
  int best = -1, best_size = -1;
  for (int j = 0; j < model->njnt; ++j) {
    if (model->jnt_type[j] != mjJNT_FREE) continue;
    const int b = model->jnt_bodyid[j];
    int size = 0;
    for (int c = b + 1; c < model->nbody; ++c) {
      int up = c;
      while (up > b) up = model->body_parentid[up];
      size += up == b;
    }
    if (size > best_size) best = b, best_size = size;
  }
  if (best >= 0) return best;
  return model->nbody > 1 ? 1 : 0;
}

bool isStripPath(const std::string& path) { return path.size() > 4 && path.substr(path.size() - 4) == ".png"; }

FrameWriter::FrameWriter(const std::string& path, int width, int height, double fps, int strip_frames)
    : path_(path), strip_(isStripPath(path)), strip_frames_(strip_frames) {
  std::string filter = strip_ ? "-vf tile=" + std::to_string(strip_frames) + "x1 -frames:v 1 -update 1"
                              : (path.size() > 4 && path.substr(path.size() - 4) == ".gif" ? "" : "-pix_fmt yuv420p");
  const std::string cmd = "ffmpeg -y -loglevel error -f rawvideo -pixel_format rgb24 -video_size " +
                          std::to_string(width) + "x" + std::to_string(height) + " -framerate " + std::to_string(fps) +
                          " -i - " + filter + " " + shellQuoted(path);
  pipe_ = popen(cmd.c_str(), "w");
  if (!pipe_) throw std::runtime_error("cannot start ffmpeg (is the ffmpeg package installed?)");
}

FrameWriter::~FrameWriter() {
  if (pipe_) pclose(pipe_);
}

void FrameWriter::write(const std::vector<unsigned char>& rgb) {
  if (std::fwrite(rgb.data(), 1, rgb.size(), pipe_) != rgb.size())
    throw std::runtime_error("ffmpeg stopped taking frames for " + path_);
}

}  // namespace masa::render
