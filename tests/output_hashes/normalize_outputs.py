#!/usr/bin/env python3
"""normalize_outputs.py DIR: prints one sha256 per output file of hash_run.sh after taking out what
depends on the wall clock: progress lines (ETA), wall-clock seconds, the map's creation time and
the checksum that covers it, and nanosecond timings."""
import hashlib, json, os, re, sys

WALL_KEYS = {"wall_seconds", "created_utc", "checksum", "raw_ns", "decorated_ns", "overhead_ns",
             "ratio", "map_query_ns", "wall_s", "elapsed_s", "wall_time_s"}

def scrub(value):
    if isinstance(value, dict):
        return {k: scrub(v) for k, v in value.items() if k not in WALL_KEYS and "wall" not in k}
    if isinstance(value, list):
        return [scrub(v) for v in value]
    return value

def text(path):
    lines = []
    for line in open(path, errors="replace"):
        if "ETA" in line or "\r" in line or line.startswith("created "):
            continue
        line = re.sub(r"wall [0-9.]+ ?(s|min|ms)", "wall X", line)
        line = re.sub(r"[0-9.]+ ns", "X ns", line)
        lines.append(line)
    return "".join(lines).encode()

d = sys.argv[1]
for name in sorted(os.listdir(d)):
    if name == "sums.txt":
        continue
    path = os.path.join(d, name)
    if name.endswith(".json"):
        data = json.dumps(scrub(json.load(open(path))), sort_keys=True).encode()
    elif name.endswith(".png"):
        data = open(path, "rb").read()
    else:
        data = text(path)
    print(hashlib.sha256(data).hexdigest(), name)
