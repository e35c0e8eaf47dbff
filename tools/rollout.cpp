// masa_rollout: run a random policy or a trained model in a task; print per-term rewards and
// episode statistics; optionally record a video (.mp4/.gif) or an image strip (.png).
//   masa_rollout --task a1_beam --episodes 3
//   masa_rollout --task a1_beam --checkpoint runs/x/model.bin --deterministic
//   xvfb-run -a masa_rollout --task a1_beam --video a1.mp4 --max-steps 200
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "common/core/build_info.hpp"
#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"
#include "common/model/actor_critic.hpp"
#include "common/model/diag_gaussian.hpp"
#include "common/render/offscreen_renderer.hpp"
#include "common/render/strip_sampler.hpp"
#include "common/sim/registry.hpp"
#include "tasks/tasks.hpp"

using namespace masa;

int main(int argc, char** argv) {
  CLI::App app{"Roll out a policy in a masa task and report rewards term by term"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string task_name = "humanoid_tightrope", checkpoint, video;
  std::vector<std::string> overrides;
  int episodes = 3, max_steps = 0, width = 640, height = 480, strip = 8;
  std::uint64_t seed = 0;
  double fps = 30.0, camera_distance = 0.0;
  bool deterministic = false;
  app.add_option("--task", task_name, "task name")->capture_default_str();
  app.add_option("--set", overrides, "config override key.path=value (repeatable)");
  app.add_option("--episodes", episodes, "episodes to run")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of resets and random actions")->capture_default_str();
  app.add_option("--checkpoint", checkpoint, "model file saved by masa (default: uniform random actions)");
  app.add_flag("--deterministic", deterministic, "act with the policy mean instead of sampling");
  app.add_option("--max-steps", max_steps, "cut episodes after this many steps (0: the task's limit)");
  app.add_option("--video", video, "record to .mp4, .gif, or .png (an image strip); needs a display or xvfb-run");
  app.add_option("--fps", fps, "video frame rate")->capture_default_str();
  app.add_option("--width", width, "video width")->capture_default_str();
  app.add_option("--height", height, "video height")->capture_default_str();
  app.add_option("--strip-frames", strip, "frames in a .png strip")->capture_default_str();
  app.add_option("--camera-distance", camera_distance, "camera distance in m (default: from the model's size)");
  CLI11_PARSE(app, argc, argv);

  try {
    overrides.insert(overrides.begin(), "task=" + task_name);
    const auto rc = config::loadRunConfig(config::defaultConfigsDir(), overrides);
    const auto spec = sym::SymmetrySpec::load(rc.spec_path);
    task::TaskFactory factory(task::taskCatalog(), rc.task, spec, rc.env, rc.origin);
    auto env = factory.create();

    std::unique_ptr<model::ActorCritic<float>> policy;
    if (!checkpoint.empty()) {
      policy = std::make_unique<model::ActorCritic<float>>(spec, rc.model);
      std::ifstream in(checkpoint, std::ios::binary);
      if (!in) throw std::runtime_error(checkpoint + ": cannot open the checkpoint");
      policy->load(in, checkpoint);
    }

    std::unique_ptr<render::OffscreenRenderer> renderer;
    std::unique_ptr<render::FrameWriter> writer;
    int render_every = 1, frames = 0;
    bool is_strip = false;
    render::StripSampler sampler(std::max(1, strip));  // a strip shows the first episode
    const int limit = max_steps > 0 ? std::min(max_steps, env->maxEpisodeSteps()) : env->maxEpisodeSteps();
    if (!video.empty()) {
      renderer = std::make_unique<render::OffscreenRenderer>(env->model(), width, height);
      // Small scenes (TriFinger) from their extent; long ones (a 100 m rope) at a walking robot's scale.
      if (camera_distance <= 0) camera_distance = std::min(3.0, 1.5 * env->model()->stat.extent);
      renderer->trackBody(render::rootBody(env->model()), camera_distance, 135.0, -20.0);
      is_strip = render::isStripPath(video);
      if (!is_strip) writer = std::make_unique<render::FrameWriter>(video, renderer->width(), renderer->height(), fps);
      render_every = std::max(1, static_cast<int>(std::lround(1.0 / (fps * env->controlTimestep()))));
    }

    Rng rng(seed);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    Eigen::VectorXf obs(env->obsDim()), act(env->actDim()), log_std(env->actDim());
    if (policy) policy->logStd(log_std);
    const auto& names = env->rewardTermNames();
    std::vector<double> term_total(names.size(), 0.0);
    double return_total = 0.0, length_total = 0.0;
    int successes = 0;

    std::printf("%s, %s policy, %d episode(s), %.4f s per step\n", rc.task.c_str(),
                policy ? model::methodName(rc.method).c_str() : "random", episodes, env->controlTimestep());
    for (int e = 0; e < episodes; ++e) {
      env->reset(rng);
      for (int t = 0; t < limit; ++t) {
        if (policy) {
          env->observe(obs.data());
          const auto mean = policy->actMean(obs);
          if (deterministic) {
            act = mean.col(0);
          } else {
            Eigen::MatrixXf sample(env->actDim(), 1);
            model::gaussian::sample<float>(mean, log_std, rng, sample);
            act = sample.col(0);
          }
        } else {
          for (int k = 0; k < env->actDim(); ++k) act(k) = uniform(rng);
        }
        const task::StepOutcome o = env->step(act.data());
        const bool last = o.terminated || o.truncated || t + 1 == limit;
        if (writer && t % render_every == 0) {
          writer->write(renderer->render(env->data()));
          ++frames;
        } else if (is_strip && e == 0 && sampler.wants(t)) {
          sampler.add(t, renderer->render(env->data()));
        } else if (is_strip && e == 0 && last) {
          sampler.addLast(t, renderer->render(env->data()));
        }
        if (o.terminated || o.truncated) break;
      }
      const task::EpisodeStats& s = env->episode();
      std::printf("episode %d: length %d, return %.3f, %s%s\n", e, s.length, s.ret,
                  s.terminated ? "terminated" : (s.truncated ? "time limit" : "cut"),
                  s.has_success ? (s.success ? ", success" : ", no success") : "");
      for (size_t k = 0; k < names.size(); ++k) term_total[k] += s.term_sums[k];
      return_total += s.ret;
      length_total += s.length;
      successes += s.success ? 1 : 0;
    }
    std::printf("mean over %d episode(s): return %.3f, length %.1f", episodes, return_total / episodes,
                length_total / episodes);
    if (env->episode().has_success) std::printf(", success rate %.2f", double(successes) / episodes);
    std::printf("\nreward terms (mean sum per episode):\n");
    for (size_t k = 0; k < names.size(); ++k) std::printf("  %-14s %10.3f\n", names[k].c_str(), term_total[k] / episodes);
    if (is_strip) frames = sampler.writeStrip(video, renderer->width(), renderer->height());
    writer.reset();  // ffmpeg finishes the file
    if (!video.empty()) std::printf("wrote %s (%d frames)\n", video.c_str(), frames);
  } catch (const ConfigError& e) {
    std::cerr << "masa_rollout: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "masa_rollout: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
