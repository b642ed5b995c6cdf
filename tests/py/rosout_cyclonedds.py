#!/usr/bin/env python3
"""A third-party reader of ``/rosout`` on Cyclone DDS (the DDS of rmw_cyclonedds): reads
rcl_interfaces/Log from ``rt/rosout`` (reliable, transient local, as rcl's rosout) for a number of
seconds and prints what came as one JSON list of ``{"level", "name", "msg", "file", "line"}``. It prints ``ready`` on
stderr once its reader is open.

    rosout_cyclonedds.py --domain 53 --seconds 6
"""

import argparse
import json
import sys
import time
from dataclasses import dataclass

from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from ros_types import Time


@dataclass
class Log(IdlStruct, typename="rcl_interfaces::msg::dds_::Log_"):
    stamp: Time
    level: t.uint8
    name: str
    msg: str
    file: str
    function: str
    line: t.uint32


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--seconds", type=float, required=True)
    a = ap.parse_args()
    dp = DomainParticipant(a.domain)
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal,
              Policy.History.KeepLast(1000))
    reader = DataReader(dp, Topic(dp, "rt/rosout", Log), qos=qos)
    print("ready", file=sys.stderr, flush=True)
    got = []
    end = time.time() + a.seconds
    while time.time() < end:
        # A writer going away shows as an invalid sample (no data): skipped.
        got += [{"level": s.level, "name": s.name, "msg": s.msg, "file": s.file, "line": s.line}
                for s in reader.take(N=100) if isinstance(s, Log)]
        time.sleep(0.02)
    print(json.dumps(got))


if __name__ == "__main__":
    main()
