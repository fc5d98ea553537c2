#!/usr/bin/env python3
"""A graspopt hand agent in Python, speaking the documented protocol (docs/protocol.md) in JSON.

It stands where a real robot's driver would: it declares itself alive, receives trial commands,
"executes" each one and publishes the contact clouds its fingertip sensors measured. Here the
measurements come from a recording (JSON lines, as written by `graspopt record`): each command is
answered with the recorded grasp nearest to its parameters. Replace `measure()` with your robot.
A hand with force/torque sensors in its fingertips: ft_hand_agent.py, built on this file.

    pip install eclipse-zenoh~=1.10.0
    python3 hand_agent.py --connect tcp/127.0.0.1:7447 --run mug --id py-hand-1 \
        --recording mug.jsonl

Only the Python standard library and eclipse-zenoh are needed.
"""

import argparse
import json
import math
import queue
import random
import socket
import sys
import threading
import time

import zenoh

WIRE_VERSION = 4  # every payload carries it; a mismatch is refused


def load_recording(path, check=None):
    """The recorded grasps: dicts with params, hand, palm_pose, fingers (or fingertips), min_gap.
    `check(grasp)`, if given, returns what is wrong with a grasp (None: nothing)."""
    grasps = []
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            if line.strip():
                try:
                    grasp = json.loads(line)
                except json.JSONDecodeError as e:
                    sys.exit(f"recording {path}, line {n}: {e}")
                problem = check(grasp) if check else None
                if problem:
                    sys.exit(f"recording {path}, line {n}: {problem}")
                grasps.append(grasp)
    if not grasps:
        sys.exit(f"recording {path} holds no grasps")
    return grasps


def measure(grasps, command):
    """What the fingers touched when the hand executed `command`: the nearest recorded grasp."""
    params = command["params"]
    candidates = [g for g in grasps if len(g["params"]) == len(params)]
    if not candidates:
        return None, f"the recording has no grasp with {len(params)} parameters"
    best = min(candidates, key=lambda g: math.dist(g["params"], params))
    if best["hand"] != command["hand"]:
        return None, f"recorded with a {best['hand']} hand, the trial asks for {command['hand']}"
    return best, None


PHASES = ("starting", "held", "settled")
SETTLE_AFTER_S = 2.0


def claim_of(key):
    """The claim a claim key names, (number, phase), or None for another key."""
    number, phase = key.split("/")[-2:]
    if len(number) != 16 or phase not in PHASES:
        return None
    try:
        return int(number, 16), phase
    except ValueError:
        return None


def gives_way_to(mine, settled, other):
    """Whether a holder with number `mine` (settled or not) gives way to the claim `other`:
    before it has held its place for SETTLE_AFTER_S, to a smaller number held (taken at the
    same moment) or to anyone settled (this one is the newcomer whose view came late); once
    settled, only to a smaller number settled."""
    number, phase = other
    if number == mine or phase == "starting":
        return False
    if phase == "held":
        return not settled and number < mine
    return not settled or number < mine


class Place:
    """A hand's place in a run, held (see take_place): keep it while the hand runs, undeclare
    it when the hand stops. After SETTLE_AFTER_S it declares itself settled. It watches the
    claims of the place: should another hand with the id come first (see gives_way_to; the
    two took it at the same moment and each one's claim reached the other late), `lost`
    turns to the reason this hand gives way, and `on_lost()` is called (from Zenoh's
    thread): take no more commands, and exit."""

    def __init__(self, session, claims_key, nonce, held, lost_why, on_lost):
        self.lost = None
        self._held = held
        self._settled = None
        self._is_settled = False
        self._lock = threading.Lock()

        def watch(sample):
            claim = claim_of(str(sample.key_expr))
            if not claim or sample.kind != zenoh.SampleKind.PUT:
                return
            with self._lock:
                if self.lost is None and gives_way_to(nonce, self._is_settled, claim):
                    self.lost = lost_why
                    on_lost()

        def settle():
            with self._lock:
                if self.lost is not None or self._stopped:
                    return
                # Settled before the token is out: a claim seen from now on is judged as
                # the others will judge this one's.
                self._is_settled = True
                self._settled = session.liveliness().declare_token(
                    f"{claims_key}/{nonce:016x}/settled")

        self._stopped = False
        self._watch = session.liveliness().declare_subscriber(
            f"{claims_key}/**", watch, history=True)
        self._timer = threading.Timer(SETTLE_AFTER_S, settle)
        self._timer.daemon = True
        self._timer.start()

    def undeclare(self):
        self._timer.cancel()
        with self._lock:
            self._stopped = True
            if self._settled is not None:
                self._settled.undeclare()
        self._watch.undeclare()
        self._held.undeclare()


def gives_way(run, hand_id, what):
    """The error of a hand that gives way to another with its id (the words of graspopt's
    own agents)."""
    return (f'run "{run}": another agent, a hand with the id {hand_id}, {what}: '
            "this one gives way (give it another --id)")


def already_has(run, hand_id, host):
    """The error of a hand whose id is held by a running hand (on `host`, if known)."""
    on = f", alive on host {host}" if host else ""
    return (f'run "{run}" already has a hand with the id {hand_id}{on}: '
            "stop it first, or give this one another --id")


def take_place(session, prefix, hand_id, on_lost, wait_s=5.0):
    """Makes sure this is the run's only hand with this id, as graspopt's own agents do
    (docs/reliability.md), and returns the Place that holds it (keep it).

    First waits (up to wait_s) until no hand with the id is alive: six empty answers in a
    row, 0.2 s apart. Then claims the place with a random number and looks at the other
    claims twice, 0.15 s apart: a held claim, then the smallest number, comes first; seeing
    none, holds the place and looks once more. Exits if the place stays taken. While held,
    the place watches for a claim that comes first (see Place and gives_way_to): liveliness
    that came too late for these looks (a loaded machine) still leaves one hand with the id,
    and a newcomer whose view came late gives way to the hand that held the place before."""
    deadline = time.monotonic() + wait_s
    run = prefix.split("/")[1]

    def keys(key_expr):
        return [str(r.ok.key_expr) for r in session.liveliness().get(key_expr) if r.ok]

    free = 0
    while free < 6:
        holders = keys(f"{prefix}/alive/hand/*/{hand_id}/**")
        free = 0 if holders else free + 1
        if holders and time.monotonic() >= deadline:
            sys.exit(already_has(run, hand_id, holders[0].split("/")[4]))
        time.sleep(0.2)

    claims_key = f"{prefix}/claim/hand/{hand_id}"
    nonce = random.getrandbits(64)

    def claims():
        return [c for c in map(claim_of, keys(f"{claims_key}/**")) if c]

    def blocker(seen):
        others = [c for c in seen if c[0] != nonce]
        holding = sorted((c for c in others if c[1] != "starting"),
                         key=lambda c: (-PHASES.index(c[1]), c[0]))
        return (holding or [None])[0] or next(
            (c for c in sorted(others) if c[0] < nonce), None)

    starting = session.liveliness().declare_token(f"{claims_key}/{nonce:016x}/starting")
    while True:
        seen = None
        for _ in range(2):
            time.sleep(0.15)
            seen = blocker(claims())
            if seen:
                break
        if not seen:
            held = session.liveliness().declare_token(f"{claims_key}/{nonce:016x}/held")
            time.sleep(0.15)
            seen = next((c for c in claims() if gives_way_to(nonce, False, c)), None)
            if not seen:
                why = gives_way(run, hand_id, "took its place at the same moment and keeps it")
                place = Place(session, claims_key, nonce, held, why, on_lost)
                starting.undeclare()
                return place
            held.undeclare()
        if time.monotonic() >= deadline:
            starting.undeclare()
            if seen[1] != "starting":
                sys.exit(already_has(run, hand_id, None))
            sys.exit(gives_way(run, hand_id, "is taking its place at the same moment"))


def clouds_of(grasps, command, worker):
    """The answer to `command`: the topic (below the run's prefix) and the ContactClouds message
    of the nearest recorded grasp, or none and the reason in `error`."""
    grasp, error = measure(grasps, command)
    return "clouds", {
        "wire": WIRE_VERSION,
        "run_id": command["run_id"],
        "trial_id": command["trial_id"],
        "attempt": command["attempt"],
        "worker": worker,
        "hand": command["hand"],
        "palm_pose": grasp["palm_pose"] if grasp else command["palm_pose"],
        "fingers": grasp.get("fingers", []) if grasp else [],
        "min_gap": grasp.get("min_gap") if grasp else None,
        "error": error,
        "executed_ms": int(time.time() * 1000),
    }


def argument_parser(description):
    """The flags every hand agent here takes."""
    ap = argparse.ArgumentParser(description=description.splitlines()[0])
    ap.add_argument("--connect", required=True, help="router or peer endpoint, e.g. tcp/10.0.0.5:7447")
    ap.add_argument("--run", required=True, help="the run to join")
    ap.add_argument("--id", default="py-hand-1", help="this worker's id (unique in the run)")
    ap.add_argument("--recording", required=True, help="JSON lines of recorded grasps")
    ap.add_argument("--trial-cost-ms", type=int, default=0, help="minimum duration of a trial")
    ap.add_argument("--zenoh-config", help="a Zenoh settings file (JSON5), e.g. a role's file of "
                    "deploy/zenoh/secure/ with its user name and password; --connect still "
                    "names the endpoint")
    return ap


def serve(args, grasps, answer, topic="clouds"):
    """Joins the run as hand `args.id` and answers each trial command sent to it with
    `answer(grasps, command, worker)`, which returns the topic (below `graspopt/<run>/`) and
    the JSON message to put there, until interrupted. `topic` is the one it publishes on
    (clouds or wrenches): its liveliness token says so, for `graspopt topic list`."""
    if args.zenoh_config:
        conf = zenoh.Config.from_file(args.zenoh_config)
    else:
        conf = zenoh.Config()
        conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", json.dumps([args.connect]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    session = zenoh.open(conf)

    prefix = f"graspopt/{args.run}"
    # A key chunk: ASCII letters, digits, '-', '_', '.', at most 64, not starting with '.'.
    host = "".join(c if (c.isascii() and c.isalnum()) or c in "-_." else "_"
                   for c in socket.gethostname())[:64].lstrip(".") or "host"
    # The commands' samples, and None when the place is lost (see Place).
    incoming = queue.Queue(256)

    def wake():
        try:
            incoming.put_nowait(None)
        except queue.Full:
            pass  # the loop is busy with commands: it looks at place.lost before each

    place = take_place(session, prefix, args.id, wake)
    commands = session.declare_subscriber(f"{prefix}/hand/{args.id}/command", incoming.put)
    # The /json asks the coordinator for JSON commands; the last chunk names what it publishes.
    token = session.liveliness().declare_token(
        f"{prefix}/alive/hand/{host}/{args.id}/json/{topic}")
    print(f"{args.id}: {len(grasps)} recorded grasps, waiting for trials on {args.connect}",
          file=sys.stderr, flush=True)

    bad = 0
    try:
        while True:
            sample = incoming.get()
            if place.lost:
                sys.exit(place.lost)
            started = time.monotonic()
            try:
                command = json.loads(sample.payload.to_bytes())
                if not isinstance(command, dict):
                    raise ValueError("not a JSON object")
                if command.get("wire") != WIRE_VERSION:
                    raise ValueError(f"wire version {command.get('wire')}, expected {WIRE_VERSION}")
                if command["worker"] != args.id:
                    raise ValueError(f"command for worker {command['worker']}")
            except (ValueError, KeyError, TypeError) as e:
                bad += 1
                print(f"{args.id}: bad command ({bad} bad messages): {e}", file=sys.stderr, flush=True)
                continue
            topic, message = answer(grasps, command, args.id)
            rest = args.trial_cost_ms / 1000 - (time.monotonic() - started)
            if rest > 0:
                time.sleep(rest)
            session.put(f"{prefix}/{topic}", json.dumps(message).encode(),
                        encoding=zenoh.Encoding.APPLICATION_JSON,
                        congestion_control=zenoh.CongestionControl.BLOCK)
    except KeyboardInterrupt:
        pass
    finally:
        token.undeclare()
        commands.undeclare()
        place.undeclare()
        session.close()


def main():
    args = argument_parser(__doc__).parse_args()
    serve(args, load_recording(args.recording), clouds_of)


if __name__ == "__main__":
    main()
