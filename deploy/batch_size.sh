# Sizes the batch for the environments a launch asks for (sourced by deploy/train.sh and the
# cluster launchers): the environments go to the learner's own key (ppo.num_envs, or sac.num_envs
# for the off-policy learner). A task file or recipe sizes its minibatches for its own ppo.num_envs (the
# task files: 4096 environments x 32 steps in minibatches of 32768); for other environments that
# minibatch need not divide the batch, and the learner would refuse the run. So a launcher keeps
# the config's horizon and its number of minibatches per mini-epoch, and takes the minibatch size
# that divides actors x environments x horizon. A ppo.minibatch_size the user set is kept and
# checked instead: a request that cannot be met is refused here, before anything starts, saying
# which option to change.
#   size_batch PROG TOTAL_ENVS [--set key=value ...]   (the run's config options, users' included,
#                                                      but not the launch's own environments)
# Reads $build (the build folder) and user_sets (the user's own --set options). Sets batch_sets
# (the --set options to add after the config's, the environments included) and batch_summary
# (what was chosen, one line).
# Returns 2 after printing why, to standard error.
size_batch() {
  local prog=$1 envs=$2
  shift 2
  local resolved shape section
  resolved=$("$build/tools/masa_config" "$@") || { echo "$prog: the configuration above is refused" >&2; return 2; }
  shape=$("$build/tools/masa_config" --rollout "$@") || return 2
  section=$(shape_key section <<< "$shape")
  batch_sets=(--set "$section.num_envs=$envs")
  if [ "$section" = sac ]; then
    batch_summary="$envs environments x horizon $(shape_key horizon <<< "$shape"), off-policy (no PPO minibatches to size)"
    return 0
  fi
  local config_envs horizon config_minibatch
  config_envs=$(shape_key num_envs <<< "$shape")
  horizon=$(shape_key horizon <<< "$shape")
  config_minibatch=$(ppo_key minibatch_size <<< "$resolved")
  local batch=$((envs * horizon)) shape="$envs environments x horizon $horizon"

  local set user_minibatch=""
  for set in "${user_sets[@]+"${user_sets[@]}"}"; do
    [[ $set == ppo.minibatch_size=* ]] && user_minibatch=${set#*=}
  done
  if [ -n "$user_minibatch" ]; then
    if ((batch % config_minibatch != 0)); then
      echo "$prog: --set ppo.minibatch_size=$config_minibatch does not divide the batch, $shape = $batch samples:" \
           "give a divisor of $batch (or leave ppo.minibatch_size out and the launcher sizes it), or change --envs" >&2
      return 2
    fi
    batch_summary="$shape = $batch samples per update, minibatches of $config_minibatch (as set)"
    return 0
  fi
  # The config's minibatches per mini-epoch, then the nearest count that divides this batch.
  local wanted=$(((config_envs * horizon + config_minibatch / 2) / config_minibatch))
  ((wanted >= 1)) || wanted=1
  ((wanted <= batch)) || wanted=$batch
  local count=$wanted d
  for ((d = 0; d < batch; ++d)); do
    if ((batch % (wanted + d) == 0)); then count=$((wanted + d)); break; fi
    if ((wanted - d >= 1 && batch % (wanted - d) == 0)); then count=$((wanted - d)); break; fi
  done
  local minibatch=$((batch / count))
  batch_sets+=(--set "ppo.minibatch_size=$minibatch")
  batch_summary="$shape = $batch samples per update, $count minibatches of $minibatch"
  [ "$minibatch" = "$config_minibatch" ] ||
    batch_summary+=" (the config's $config_minibatch is for $config_envs environments; --set ppo.minibatch_size=N to choose)"
}

# The value of KEY in `masa_config --rollout`'s output on standard input (section, num_envs,
# horizon, max_updates, max_policy_lag: the numbers of the learner's own section).
shape_key() {
  sed -n "s/^$1: //p"
}

# The value of KEY in the ppo section of a resolved config on standard input.
ppo_key() {
  awk -v key="$1:" '/^[^ ]/ { in_ppo = ($0 == "ppo:") } in_ppo && $1 == key { print $2; exit }'
}
