// masa_eval: measure a trained policy in its own task, with the run's own configuration.
//   masa_eval runs/a1_beam_masa_20261130_120000            (a run directory: its policy.bin)
//   masa_eval tasks/a1_beam/policy/policy.bin --episodes 20 --seed 0
//   masa_eval runs/x/checkpoint.bin --sample               (a learner checkpoint, next to its config.yaml)
//   masa_eval runs/a1_sac_masa --seed 1000000              (masa_sac's policy.bin: tanh(mean), its own eval episodes)
//   xvfb-run -a masa_eval runs/x --video a1.png            (an image strip of episode 0; or .mp4 / .gif)
//   masa_eval runs/x/checkpoint.bin --save-policy tasks/a1_beam/policy/policy.bin   (ship it)
// Prints return, length, the task's progress figures (metres along the beam, cube pose error,
// seconds the pole stayed up), reward terms and success rate over N episodes, each reset from its
// own seed (seed + k); --csv writes one row per episode. Relative paths are the caller's.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/core/build_info.hpp"
#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"
#include "common/policy/policy_file.hpp"
#include "common/render/offscreen_renderer.hpp"
#include "common/render/strip_sampler.hpp"
#include "common/sim/policy_evaluator.hpp"
#include "learner/run_dir/checkpoint.hpp"
#include "learner/ppo_algorithm.hpp"
#include "tasks/tasks.hpp"

using namespace masa;
namespace fs = std::filesystem;

namespace {

// A run directory (its policy.bin, else its checkpoint.bin), a policy file, or a checkpoint file
// (with the config.yaml of its run directory).
policy::LoadedPolicy loadTarget(const std::string& target, const std::vector<std::string>& overrides) {
  fs::path p = fs::absolute(target);
  if (!fs::exists(p)) throw std::runtime_error(target + ": no such file or directory");
  if (fs::is_directory(p)) {
    if (fs::exists(p / "policy.bin")) {
      p /= "policy.bin";
    } else if (fs::exists(p / "checkpoint.bin")) {
      p /= "checkpoint.bin";
    } else {
      throw std::runtime_error(target + ": a directory without policy.bin or checkpoint.bin (not a run directory)");
    }
  }
  if (policy::isPolicyFile(p.string())) {
    if (!overrides.empty()) throw std::runtime_error("--set applies to checkpoints only: a policy file is evaluated as trained");
    return policy::loadPolicyFile(p.string());
  }
  if (!learner::isCheckpointFile(p.string()))
    throw std::runtime_error(target + ": neither a masa policy file nor a learner checkpoint");
  const fs::path config = p.parent_path() / "config.yaml";
  if (!fs::exists(config)) throw std::runtime_error(p.string() + ": a checkpoint needs its run's config.yaml beside it");
  policy::LoadedPolicy lp;
  lp.source = p.string();
  lp.config = config::loadRunConfig(config::defaultConfigsDir(), overrides, config.string());
  // An off-policy run's checkpoint holds no policy (older ones held PPO's unused networks).
  if (lp.config.learner != "ppo")
    throw std::runtime_error(p.string() + ": the checkpoint of a run with learner: " + lp.config.learner + " holds no policy to " +
                             "evaluate: evaluate the policy.bin beside it");
  lp.spec = sym::SymmetrySpec::load(lp.config.spec_path);
  lp.model = std::make_unique<model::ActorCritic<float>>(lp.spec, lp.config.model);
  learner::loadPpoCheckpointModel(p.string(), *lp.model);
  return lp;
}

void writeCsv(const std::string& path, const task::EvalSummary& s) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write");
  f << "episode,seed,return,length,terminated,success";
  for (const auto& n : s.progress_names) f << ',' << n;
  for (const auto& n : s.term_names) f << ",term_" << n;
  f << '\n';
  f.precision(9);
  for (size_t k = 0; k < s.episodes.size(); ++k) {
    const auto& e = s.episodes[k];
    f << k << ',' << e.seed << ',' << e.ret << ',' << e.length << ',' << (e.terminated ? 1 : 0) << ',' << e.success;
    for (double v : e.progress) f << ',' << v;
    for (double v : e.terms) f << ',' << v;
    f << '\n';
  }
}

// The caller's label (e.g. the method and seed, for strips compared side by side), the time and the
// task's progress figures on each frame.
std::string frameLabel(const std::string& prefix, const task::Task& task, int t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "t %.2f s", (t + 1) * task.controlTimestep());
  std::string label = prefix.empty() ? buf : prefix + "   " + buf;
  const auto names = task.progressNames();
  std::vector<double> values(names.size());
  if (!values.empty()) task.progress(values.data());
  for (size_t i = 0; i < names.size(); ++i) {
    std::snprintf(buf, sizeof buf, "   %.40s %.2f", names[i].c_str(), values[i]);
    label += buf;
  }
  return label;
}

// Films one episode (replayed alone from its seed). A .png strip shows `strip` frames spread
// evenly over the whole episode, however short (render::StripSampler).
void film(const task::TaskFactory& factory, model::ActorCritic<float>& model, task::EvalOptions o, uint64_t seed,
          const std::string& video, const std::string& label, int width, int height, int strip, double fps,
          double camera_distance) {
  o.episodes = 1;
  o.seed = seed;
  o.threads = 1;
  const auto env = factory.create();
  Rng reset_rng(seed);
  env->reset(reset_rng);
  render::OffscreenRenderer renderer(env->model(), width, height);
  if (camera_distance <= 0) camera_distance = render::robotViewDistance(env->model(), env->data());
  renderer.trackBody(render::rootBody(env->model()), camera_distance, 135.0, -20.0);
  const bool is_strip = render::isStripPath(video);
  const int every = std::max(1, static_cast<int>(std::lround(1.0 / (fps * env->controlTimestep()))));
  render::StripSampler sampler(strip);
  std::unique_ptr<render::FrameWriter> writer;
  if (!is_strip) writer = std::make_unique<render::FrameWriter>(video, renderer.width(), renderer.height(), fps);
  int frames = 0;
  task::PolicyEvaluator(factory, model).run(o, [&](int, int t, const task::Task& task, bool last) {
    if (is_strip) {
      if (sampler.wants(t)) sampler.add(t, renderer.render(task.data(), frameLabel(label, task, t)));
      else if (last) sampler.addLast(t, renderer.render(task.data(), frameLabel(label, task, t)));
    } else if (t % every == 0) {
      writer->write(renderer.render(task.data(), frameLabel(label, task, t)));
      ++frames;
    }
  });
  if (is_strip) frames = sampler.writeStrip(video, renderer.width(), renderer.height());
  writer.reset();  // ffmpeg finishes the file
  std::printf("wrote %s (%d frames of episode seed %llu)\n", video.c_str(), frames, static_cast<unsigned long long>(seed));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Evaluate a trained masa policy in its task (return, progress, success, reward terms)"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string target, video, csv, save_policy, label;
  std::vector<std::string> overrides;
  task::EvalOptions o;
  bool sample = false, per_episode = false;
  int width = 640, height = 480, strip = 8, film_episode = 0;
  double fps = 30.0, camera_distance = 0.0;
  app.add_option("target", target, "run directory, policy file (policy.bin) or learner checkpoint")->required();
  app.add_option("--episodes", o.episodes, "episodes, each reset from its own seed")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", o.seed, "episode k resets from seed + k")->capture_default_str();
  app.add_flag("--sample", sample, "sample actions from the policy (default: its mean; tanh(mean) for a SAC policy, which cannot be sampled)");
  app.add_option("--max-steps", o.max_steps, "cut episodes after this many steps (0: the task's limit)");
  app.add_option("--threads", o.threads, "threads stepping the environments")->capture_default_str()
      ->check(CLI::Range(1, 1024));
  app.add_option("--set", overrides, "config override for a checkpoint's run (e.g. env.max_episode_steps=500)");
  app.add_option("--csv", csv, "write one row per episode to this file");
  app.add_flag("--per-episode", per_episode, "print one line per episode");
  app.add_option("--save-policy", save_policy, "also write the target as a policy file (e.g. from a checkpoint, to ship it)");
  app.add_option("--video", video, "film one episode: .mp4, .gif, or .png (an image strip); needs a display or xvfb-run");
  app.add_option("--film-episode", film_episode, "which episode to film (its seed is seed + this)")->capture_default_str();
  app.add_option("--label", label, "text at the start of every filmed frame's caption (e.g. the method and seed)");
  app.add_option("--strip-frames", strip, "frames in a .png strip")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--fps", fps, "video frame rate")->capture_default_str()->check(CLI::Range(1, 1000));
  app.add_option("--width", width, "video width")->capture_default_str()->check(CLI::Range(16, 8192));
  app.add_option("--height", height, "video height")->capture_default_str()->check(CLI::Range(16, 8192));
  app.add_option("--camera-distance", camera_distance, "camera distance in m (default: from the model's size)");
  CLI11_PARSE(app, argc, argv);
  o.deterministic = !sample;

  try {
    policy::LoadedPolicy p = loadTarget(target, overrides);
    const double sym_error = policy::checkPolicySymmetry(p);
    task::TaskFactory factory(task::taskCatalog(), p.config.task, p.spec, p.config.env, p.config.origin);
    const bool squashed = p.model->config().squash == model::ActionSquash::kTanh;
    const char* acting = !o.deterministic ? "sampled" : squashed ? "tanh(mean)" : "mean";
    std::printf("%s / %s from %s, %d episode(s), %s actions, seeds %llu..%llu\n", p.config.task.c_str(),
                model::methodName(p.config.method).c_str(), target.c_str(), o.episodes, acting,
                static_cast<unsigned long long>(o.seed),
                static_cast<unsigned long long>(o.seed + o.episodes - 1));
    if (p.config.method == model::Method::kMasa) std::printf("equivariance checked on load: worst error %.1e\n", sym_error);
    task::PolicyEvaluator evaluator(factory, *p.model);
    const task::EvalSummary s = evaluator.run(o);
    if (per_episode)
      for (size_t k = 0; k < s.episodes.size(); ++k) {
        const auto& e = s.episodes[k];
        std::printf("episode %zu (seed %llu): return %.3f, length %d, %s", k, static_cast<unsigned long long>(e.seed),
                    e.ret, e.length, e.terminated ? "terminated" : "time limit");
        for (size_t i = 0; i < e.progress.size(); ++i) std::printf(", %s %.3f", s.progress_names[i].c_str(), e.progress[i]);
        for (size_t i = 0; i < e.physics.size(); ++i) std::printf(", %s %.3f", s.physics_names[i].c_str(), e.physics[i]);
        if (e.success >= 0) std::printf(", %s", e.success ? "success" : "no success");
        std::printf("\n");
      }
    std::printf("%s", task::formatSummary(s).c_str());
    if (!csv.empty()) {
      writeCsv(csv, s);
      std::printf("wrote %s\n", csv.c_str());
    }
    if (!save_policy.empty()) {
      policy::savePolicyFile(save_policy, p.config, *p.model);
      std::printf("wrote %s\n", save_policy.c_str());
    }
    if (!video.empty()) {
      if (film_episode < 0 || film_episode >= o.episodes) throw std::runtime_error("--film-episode must be one of the episodes");
      film(factory, *p.model, o, o.seed + static_cast<uint64_t>(film_episode), video, label, width, height, strip,
           fps, camera_distance);
    }
  } catch (const ConfigError& e) {
    std::cerr << "masa_eval: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "masa_eval: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
