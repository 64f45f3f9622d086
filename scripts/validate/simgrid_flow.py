"""Completion times of a message pattern under SimGrid's CM02 max-min network model.

Reads the JSON that `sortsim validate network` writes (nodes, link bandwidth in bytes/s,
link count, one explicit route per (src, dst) pair, messages as [src, dst, bytes,
start_s]) and prints {"completion_s": [...], "wall_s": ...} as JSON on stdout. Model CM02
with every refinement off: no cross-traffic, no TCP window bound, latency and bandwidth
factors 1, weight-S 0, zero latency, so the bandwidth a message gets is plain max-min fair
sharing of its links. Exits with 3 and names the module when SimGrid is not installed.
"""

import json
import sys
import time

try:
    from simgrid import Actor, Comm, Engine, LinkInRoute, NetZone, this_actor
except ImportError as missing:
    print(f"missing-module: {missing.name}", file=sys.stderr)
    sys.exit(3)


def main(path):
    with open(path) as f:
        spec = json.load(f)
    engine = Engine([sys.argv[0],
                     "--cfg=network/model:CM02",
                     "--cfg=network/crosstraffic:0",
                     "--cfg=network/TCP-gamma:0",
                     "--cfg=network/weight-S:0",
                     "--cfg=network/latency-factor:1",
                     "--cfg=network/bandwidth-factor:1",
                     "--cfg=maxmin/precision:1e-9",
                     "--cfg=surf/precision:1e-12",
                     "--log=root.thres:critical"])
    zone = NetZone.create_full_zone("network")
    hosts = [zone.create_host(f"n{i}", 1e9) for i in range(spec["nodes"])]
    links = [zone.create_link(f"l{j}", spec["bandwidth_bps"]).seal()
             for j in range(spec["links"])]
    for src, dst, route in spec["routes"]:
        zone.add_route(hosts[src].netpoint, hosts[dst].netpoint, None, None,
                       [LinkInRoute(links[k]) for k in route], False)
    zone.seal()

    completion = [None] * len(spec["messages"])

    def send(i, src, dst, size, start):
        this_actor.sleep_until(start)
        Comm.sendto(hosts[src], hosts[dst], size)
        completion[i] = Engine.clock

    for i, (src, dst, size, start) in enumerate(spec["messages"]):
        Actor.create(f"m{i}", hosts[src], send, i, src, dst, size, start)
    began = time.perf_counter()
    engine.run()
    wall = time.perf_counter() - began
    json.dump({"completion_s": completion, "wall_s": wall}, sys.stdout)


if __name__ == "__main__":
    main(sys.argv[1])
