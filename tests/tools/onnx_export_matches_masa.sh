#!/usr/bin/env bash
# The ONNX export against masa's own inference (issue #12 item 5). Exported by masa_export, with its
# reference (random observations and masa's action means), and checked by check_onnx_policy.py
# (onnx's checker, then a numpy walk over the graph) to 1e-5:
#   - every shipped policy (all MASA: C2 mirrors, the TriFinger's C3 and the Ant's C4 rotations);
#   - tiny runs of the other methods, one update each: SA (ELU), SASA (tanh), MA (ReLU, one-hot ids)
#     and SA without the observation normalizer;
#   - tiny masa_sac runs (MASA normalized, SA not), whose action_mean is tanh(mean).
# usage: onnx_export_matches_masa.sh BUILD_DIR WORK_DIR
# Prints PASS or FAIL lines; exits 77 (skip) when /usr/bin/python3 has no onnx (python3-onnx).
set -uo pipefail
build=$1
work=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
python=/usr/bin/python3
$python -c "import onnx, numpy" 2>/dev/null || { echo "SKIP: $python cannot import onnx and numpy (python3-onnx)"; exit 77; }
rm -rf "$work" && mkdir -p "$work"

policies=("$src"/tasks/*/policy/policy.bin)
tiny=(--set task=a1_beam --set model.policy_hidden=[16,8] --set model.critic_hidden=[16] --set ppo.num_envs=8
      --set ppo.horizon=8 --set ppo.minibatch_size=64 --set env.max_episode_steps=40 --set runner.eval_every=0)
for case in "sa elu true" "sasa tanh true" "ma relu true" "sa elu false"; do
  read -r method activation normalize <<< "$case"
  run="$work/tiny_${method}_${activation}_norm_${normalize}"
  if ! "$build/tools/masa_train" "${tiny[@]}" --set method=$method --set model.activation=$activation \
       --set model.normalize_input=$normalize --quiet --updates 1 --run-dir "$run" > "$run.log" 2>&1; then
    echo "FAIL: the tiny $method run did not train:"; tail -5 "$run.log"; exit 1
  fi
  policies+=("$run/policy.bin")
done

# masa_sac's policies (format 2: action_mean = tanh(mean), a Tanh node last), with a large last
# layer so that the means reach beyond tanh's linear range: MASA after 100 updates (normalized),
# SA before any (learning_starts not reached: no normalizer).
sac_tiny=(--task a1_beam --set "sac.policy_hidden=[16,8]" --set "sac.q_hidden=[8]" --set sac.batch_size=8
          --set sac.log_every=20 --set sac.eval_every=0 --set sac.eval_episodes=1 --set sac.checkpoint_every=0
          --set env.max_episode_steps=20 --set model.policy_last_layer_scale=3)
for case in "masa 40 140" "sa 100 60"; do
  read -r method starts steps <<< "$case"
  run="$work/tiny_sac_${method}"
  if ! "$build/tools/masa_sac" "${sac_tiny[@]}" --method $method --set sac.learning_starts=$starts --steps $steps \
       --quiet --out "$run" > "$run.log" 2>&1; then
    echo "FAIL: the tiny SAC $method run did not train:"; tail -5 "$run.log"; exit 1
  fi
  policies+=("$run/policy.bin")
done

failed=0
for policy in "${policies[@]}"; do
  dir=$(dirname "$policy")
  [ "$(basename "$dir")" = policy ] && dir=$(dirname "$dir")  # tasks/<task>/policy/policy.bin: the task
  name=$(basename "$dir")
  if ! "$build/tools/masa_export" "$policy" "$work/$name.onnx" --reference "$work/$name.txt" --samples 64 \
       > "$work/$name.log" 2>&1; then
    echo "FAIL: masa_export $policy:"; cat "$work/$name.log"; failed=1; continue
  fi
  $python "$src/tests/tools/check_onnx_policy.py" "$work/$name.onnx" "$work/$name.txt" --tolerance 1e-5 || failed=1
done
if [ $failed -ne 0 ]; then echo "FAIL: an exported policy does not match masa"; exit 1; fi
echo "PASS: ${#policies[@]} policies exported to ONNX match masa's inference to 1e-5"
