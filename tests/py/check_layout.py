#!/usr/bin/env python3
"""Checks a Foxglove layout against a recorded bag, decoding the bag with rosbags (a third-party reader).

    check_layout.py LAYOUT.json BAG [NAMESPACE]

Every panel the layout tree names must have a config (and every config a place in the tree). Every topic the
panels read is looked up in the bag (as written, else under NAMESPACE, e.g. /ship1, for relative names);
message paths (`/probes.elevations[0]`) are resolved on the topic's first decoded message and must give a
number, and the 3D panel's colour field must be a field of the point cloud. Prints JSON:
{"resolved": {path: value}, "missing": [topics the bag lacks], "short": [paths indexing past the end of an
array, e.g. a third probe of a case that has two], "panels": n}.
"""

import json
import re
import sys
from pathlib import Path

from rosbags.highlevel import AnyReader


def tree_ids(node):
    if isinstance(node, str):
        return [node]
    return tree_ids(node["first"]) + tree_ids(node["second"])


def resolve(msg, rest):
    value = msg
    for field, index in re.findall(r"\.(\w+)|\[(\d+)\]", rest):
        value = getattr(value, field) if field else value[int(index)]
    return float(value)


def main(layout_path, bag, ns=""):
    layout = json.load(open(layout_path))
    configs = layout["configById"]
    ids = tree_ids(layout["layout"])
    assert sorted(ids) == sorted(configs), f"tree {sorted(ids)} vs configs {sorted(configs)}"
    paths, clouds, topics = [], [], []
    for pid, cfg in configs.items():
        kind = pid.split("!")[0]
        if kind == "Plot":
            paths += [p["value"] for p in cfg["paths"]]
        elif kind == "3D":
            clouds += [(t, c.get("colorField")) for t, c in cfg["topics"].items()]
        elif kind in ("DiagnosticSummary", "DiagnosticStatusPanel"):
            topics.append(cfg["topicToRender"])
        elif kind == "RawMessages":
            paths.append(cfg["topicPath"])
        else:
            raise AssertionError(f"unexpected panel {pid}")
    first = {}
    with AnyReader([Path(bag)]) as reader:
        for conn, _, raw in reader.messages():
            if conn.topic not in first:
                first[conn.topic] = reader.deserialize(raw, conn.msgtype)

    def find(topic):
        for name in (topic, ns + topic):
            if name in first:
                return first[name]
        return None

    out = {"resolved": {}, "missing": [], "short": [], "panels": len(configs)}
    for p in paths:
        m = re.match(r"(/[\w/]+?)((?:\.\w+|\[\d+\])*)$", p)
        assert m, f"not a message path: {p}"
        topic, rest = m.group(1), m.group(2)
        msg = find(topic)
        if msg is None:
            out["missing"].append(topic)
            continue
        try:
            out["resolved"][p] = resolve(msg, rest)
        except IndexError:
            out["short"].append(p)
    for topic, colour in clouds:
        msg = find(topic)
        if msg is None:
            out["missing"].append(topic)
            continue
        names = [f.name for f in msg.fields]
        assert colour in names, f"{topic}: colour field {colour} not in {names}"
        out["resolved"][topic + "#" + colour] = float(msg.width)
    for topic in topics:
        msg = find(topic)
        if msg is None:
            out["missing"].append(topic)
        else:
            out["resolved"][topic] = float(len(msg.status))
    out["missing"] = sorted(set(out["missing"]))
    print(json.dumps(out))


if __name__ == "__main__":
    main(*sys.argv[1:])
