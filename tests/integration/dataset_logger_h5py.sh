# A dataset as a user makes and reads one: masa_dataset record writes a log and publishes the same
# episodes on LCM while lcm-logger records them; both logs must read back as the same dataset;
# the export must open in h5py with the layout the README shows.
#   MASA_BUILD_DIR=build bash tests/integration/dataset_logger_h5py.sh [PORT]
# SKIP (77) when lcm-logger or Debian's python3-h5py is missing.
set -uo pipefail
source "$(dirname "$0")/lib.sh"
port=${1:-7691}
tool="$build/tools/masa_dataset"
[ -x "$tool" ] || fail "$tool is missing: build first"
command -v lcm-logger >/dev/null || { echo "SKIP: lcm-logger is not installed"; exit 77; }
/usr/bin/python3 -c "import h5py" 2>/dev/null || { echo "SKIP: python3-h5py is not installed"; exit 77; }
work=$(mktemp -d /tmp/masa_dataset.XXXXXX)
url="udpm://239.255.76.67:$port?ttl=0&recv_buf_size=4194304"  # lcm-logger keeps up with a burst
trap 'kill_started; rm -rf "$work"' EXIT

lcm-logger --lcm-url="$url" --channel=MASA_DATASET --quiet "$work/logger.lcmlog" > "$work/logger.log" 2>&1 &
started_pids+=($!)
sleep 1
"$tool" record tasks/a1_beam/policy/policy.bin --episodes 3 --max-steps 300 --seed 5 --out "$work/written.lcmlog" \
  --publish --url "$url" > "$work/record.log" 2>&1 || fail "masa_dataset record failed"
sleep 1
kill -INT "${started_pids[0]}"; wait "${started_pids[0]}" 2>/dev/null
"$tool" info "$work/written.lcmlog" > "$work/written.txt" 2>&1 || fail "info on the written log failed"
"$tool" info "$work/logger.lcmlog" > "$work/logger.txt" 2>&1 || fail "info on lcm-logger's log failed"
grep -q "3 episodes, 900 transitions" "$work/written.txt" || fail "the written log does not hold 3 episodes of 300 steps: $(cat "$work/written.txt")"
# lcm-logger's recording has no seals (masa's log seals each episode): read with a warning.
grep -q "1 log(s) without seals" "$work/logger.txt" || fail "lcm-logger's log not reported unsealed: $(cat "$work/logger.txt")"
grep -q "without seals" "$work/written.txt" && fail "the written log is not sealed: $(cat "$work/written.txt")"
# Everything but the first line (event counts differ: 7 with the seals vs 9) and the unsealed
# log's warning and note must agree.
diff <(tail -n +2 "$work/written.txt") <(grep -v -e 'unsealed dataset log' -e 'note: .*no seal' "$work/logger.txt" | tail -n +2) > "$work/diff.txt" ||
  fail "lcm-logger's recording differs from the written log: $(cat "$work/diff.txt")"

"$tool" export "$work/written.lcmlog" --hdf5 "$work/data.h5" > "$work/export.log" 2>&1 || fail "export failed"
/usr/bin/python3 - "$work/data.h5" <<'PY' || fail "h5py check failed"
import sys, h5py, numpy as np
with h5py.File(sys.argv[1]) as f:
    obs, act, rew = f["observations"][:], f["actions"][:], f["rewards"][:]
    nxt, term, tout, idx = f["next_observations"][:], f["terminals"][:], f["timeouts"][:], f["episode_index"][:]
    start, length, ret = f["episodes/start"][:], f["episodes/length"][:], f["episodes/return"][:]
    assert f.attrs["task"] == "a1_beam", f.attrs["task"]
    assert obs.shape == (900, 47) and nxt.shape == (900, 47) and act.shape == (900, 12) and rew.shape == (900,)
    assert obs.dtype == np.float32 and term.dtype == np.uint8
    for k in range(3):
        s, n = start[k], length[k]
        assert (idx[s:s + n] == k).all()
        assert np.array_equal(nxt[s:s + n - 1], obs[s + 1:s + n]), "next_observations is not the next row"
        assert abs(rew[s:s + n].astype(np.float64).sum() - ret[k]) < 1e-6 * (1 + abs(ret[k]))
        assert tout[s + n - 1] == 1 - term[s + n - 1]
    print("h5py: %d transitions of %s, %d episodes" % (len(rew), f.attrs["task"], len(start)))
PY
echo "PASS: 3 episodes recorded, lcm-logger's log reads as the written one, the HDF5 export opens in h5py"
