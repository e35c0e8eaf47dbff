#!/usr/bin/env python3
"""How each Humanoid Dribbling episode of a recorded dataset ends, and where the ball is at each turn.

Reads an LCM log of masa_dataset (channel MASA_DATASET, lcmtypes/lcmt_transitions.lcm) with the
standard library only, and prints per episode: its length, why it ended (a fall: the torso more
than 0.4 m below its start; the ball: more than 1 m from the torso; else the time limit), and each
step at which the observation frame moved to the next segment (the torso yaw observation jumps)
with the ball's position relative to the torso in the new frame (ahead, lateral).

  masa_dataset record POLICY --out d.lcmlog --episodes 20 --mean
  python3 episode_ends.py d.lcmlog
Observation indices: tasks/humanoid_dribbling/README.md (1 torso z, 10 torso yaw, 20-21 ball - torso).
"""
import collections
import math
import struct
import sys

TORSO_Z, TORSO_YAW, BALL_X, BALL_Y = 1, 10, 20, 21
FALL_HEIGHT, MAX_BALL_DISTANCE = 0.4, 1.0  # the recipe humanoid_dribbling_close's


def events(path):
    data = open(path, 'rb').read()
    i = 0
    while i < len(data):
        sync, _, _, channel_len, data_len = struct.unpack('>IqqII', data[i:i + 28])
        if sync != 0xEDA1DA01:
            raise ValueError(f'{path}: no LCM event at byte {i}')
        i += 28
        channel = data[i:i + channel_len].decode()
        i += channel_len
        yield channel, data[i:i + data_len]
        i += data_len


def text(d, o):
    n, = struct.unpack('>I', d[o:o + 4])
    return d[o + 4:o + 3 + n].decode(), o + 4 + n


def transitions(d):
    o = 8 + 8  # fingerprint, utime
    _, o = text(d, o)  # task
    episode_id, _ = struct.unpack('>qi', d[o:o + 12])
    _, o = text(d, o + 12)  # policy name
    step_offset, num_steps, obs_dim, _, obs_len = struct.unpack('>5i', d[o:o + 20])
    o += 20
    obs = struct.unpack(f'>{obs_len}f', d[o:o + 4 * obs_len])
    o += 4 * obs_len
    actions_len, = struct.unpack('>i', d[o:o + 4])
    o += 4 + 4 * actions_len + 4 * num_steps
    last = d[o] != 0
    return episode_id, step_offset, num_steps, obs_dim, obs, last


def main(path):
    episodes = collections.defaultdict(list)
    for channel, d in events(path):
        if channel == 'MASA_DATASET':
            m = transitions(d)
            episodes[m[0]].append(m)
    ends = collections.Counter()
    for episode_id, messages in sorted(episodes.items()):
        messages.sort(key=lambda m: m[1])
        rows = []
        for _, _, num_steps, obs_dim, obs, last in messages:
            for t in range(num_steps + 1 if last else num_steps):
                rows.append(obs[t * obs_dim:(t + 1) * obs_dim])
        first, end = rows[0], rows[-1]
        distance = math.hypot(end[BALL_X], end[BALL_Y])
        if end[TORSO_Z] < first[TORSO_Z] - FALL_HEIGHT:
            why = 'fall'
        elif distance > MAX_BALL_DISTANCE:
            why = 'ball lost'
        else:
            why = 'time limit'
        ends[why] += 1
        turns = [k for k in range(1, len(rows)) if abs(rows[k][TORSO_YAW] - rows[k - 1][TORSO_YAW]) > 0.4]
        at_turns = '; '.join(f'step {k}: ball ahead {rows[k][BALL_X]:.2f} m, lateral {rows[k][BALL_Y]:.2f} m'
                             for k in turns)
        print(f'episode {episode_id & 0xffffffff}: {len(rows) - 1} steps, {why} (torso {end[TORSO_Z]:.2f} m high, '
              f'ball {distance:.2f} m away); turns: {at_turns or "none"}')
    print('ends:', ', '.join(f'{why} {n}' for why, n in ends.most_common()))


if __name__ == '__main__':
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
