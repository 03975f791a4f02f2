"""A second DDS participant, in its own process: records every robot's ROS 2 pose and state topics to a JSON-lines file.

Usage: python ros2_listener.py DOMAIN OUT.jsonl ID[,ID...] — prints ``ready`` once
its readers exist, and ends when every robot has published ``stop`` (or after
:data:`MOST_SECONDS`, a bound for a broken run only).
"""

from __future__ import annotations

import json
import sys
import time

MOST_SECONDS = 300.0


def main() -> int:
    from cyclonedds.domain import DomainParticipant  # here, not above: the test suite imports this module for its doctests
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic

    from mrmp.live import ros2_types
    from mrmp.live.ros2_topics import HISTORY, pose_topic, published_qos, state_topic

    domain, out, ids = int(sys.argv[1]), sys.argv[2], sys.argv[3].split(",")
    participant = DomainParticipant(domain)
    qos = published_qos()
    readers = []
    for robot in ids:
        readers.append((robot, DataReader(participant, Topic(participant, pose_topic(robot), ros2_types.PoseStamped), qos=qos)))
        readers.append((robot, DataReader(participant, Topic(participant, state_topic(robot), ros2_types.String), qos=qos)))
    print("ready", flush=True)
    stopped: set[str] = set()
    deadline = time.monotonic() + MOST_SECONDS
    with open(out, "w", encoding="utf-8") as file:
        while stopped != set(ids) and time.monotonic() < deadline:
            for robot, reader in readers:
                for sample in reader.take(N=HISTORY):
                    if isinstance(sample, ros2_types.PoseStamped):
                        position, orientation = sample.pose.position, sample.pose.orientation
                        line = {"robot": robot, "frame": sample.header.frame_id, "x": position.x, "y": position.y,
                                "qz": orientation.z, "qw": orientation.w, "stamp": sample.header.stamp.sec}  # fmt: skip
                    elif isinstance(sample, ros2_types.String):
                        line = {"robot": robot, "state": json.loads(sample.data)}
                        stopped.update([robot] if line["state"]["event"] == "stop" else [])
                    else:
                        continue  # a writer's disposal notice, not data
                    file.write(json.dumps(line) + "\n")
            file.flush()
            time.sleep(0.01)
    return 0 if stopped == set(ids) else 1


if __name__ == "__main__":
    raise SystemExit(main())
