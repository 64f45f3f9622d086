"""Completion times of a message pattern under SimGrid's CM02 max-min network model.

Reads the JSON that `sortsim validate network` writes (nodes, link bandwidth in bytes/s,
link count, one explicit route per (src, dst) pair, messages as [src, dst, bytes,
start_s]) and prints {"completion_s": [...], "wall_s": ...} as JSON on stdout. With a
"native" zone (a fat-tree or a dragonfly), SimGrid builds that cluster zone itself, routes
by its own rules, and the answer also carries "routes": SimGrid's route for each pair of
"routes", its links numbered as sortsim numbers them (both build the same cables in the same
order, one up/down pair each: sortsim link 2u is SimGrid's "..._u_UP", 2u + 1 "..._u_DOWN"). Model CM02
with every refinement off: no cross-traffic, no TCP window bound, latency and bandwidth
factors 1, weight-S 0, zero latency, so the bandwidth a message gets is plain max-min fair
sharing of its links. Exits with 3 and names the module when SimGrid is not installed.
"""

import json
import sys
import time

try:
    from simgrid import (Actor, ClusterCallbacks, Comm, DragonflyParams, Engine, FatTreeParams,
                         Link, LinkInRoute, NetZone, this_actor)
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
    native = spec.get("native")
    if native:
        hosts = native_zone(native, spec["nodes"], spec["bandwidth_bps"])
    else:
        hosts = explicit_zone(spec)

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
    answer = {"completion_s": completion, "wall_s": wall}
    if native:
        answer["routes"] = [[src, dst, [sortsim_link(link.name)
                                        for link in hosts[src].route_to(hosts[dst])[0]]]
                            for src, dst, _ in spec["routes"]]
    json.dump(answer, sys.stdout)


def explicit_zone(spec):
    zone = NetZone.create_full_zone("network")
    hosts = [zone.create_host(f"n{i}", 1e9) for i in range(spec["nodes"])]
    links = [zone.create_link(f"l{j}", spec["bandwidth_bps"]).seal()
             for j in range(spec["links"])]
    for src, dst, route in spec["routes"]:
        zone.add_route(hosts[src].netpoint, hosts[dst].netpoint, None, None,
                       [LinkInRoute(links[k]) for k in route], False)
    zone.seal()
    return hosts


def native_zone(native, nodes, bandwidth):
    """SimGrid's own cluster zone, split-duplex links, zero latency; hosts by rank."""
    hosts = [None] * nodes

    def host(zone, coord, rank):
        hosts[rank] = zone.create_host(f"n{rank}", 1e9).seal()
        return hosts[rank].netpoint, None

    callbacks = ClusterCallbacks(host, None, None)
    duplex = Link.SharingPolicy.SPLITDUPLEX
    if native["kind"] == "fat-tree":
        params = FatTreeParams(len(native["down"]), native["down"], native["up"],
                               native["parallel"])
        zone = NetZone.create_fatTree_zone("network", None, params, callbacks, bandwidth, 0,
                                           duplex)
    else:
        params = DragonflyParams([native["groups"], 1], [native["chassis"], 1],
                                 [native["routers"], 1], native["nodes_per_router"])
        zone = NetZone.create_dragonfly_zone("network", None, params, callbacks, bandwidth, 0,
                                             duplex)
    zone.seal()
    return hosts


def sortsim_link(name):
    """`..._<u>_UP` is sortsim's link 2u, `..._<u>_DOWN` its link 2u + 1."""
    rest, direction = name.rsplit("_", 1)
    pair = int(rest.rsplit("_", 1)[1])
    return 2 * pair + (1 if direction == "DOWN" else 0)


if __name__ == "__main__":
    main(sys.argv[1])
