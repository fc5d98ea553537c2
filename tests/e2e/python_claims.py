"""The example Python hand's place-taking (examples/python/hand_agent.py, take_place and
Place) against claims declared by hand on one isolated session, as another agent's would
arrive: prints what happened, one line per case, for tests/e2e/replay.rs to compare."""

import time

import zenoh

import hand_agent

conf = zenoh.Config()
conf.insert_json5("scouting/multicast/enabled", "false")
session = zenoh.open(conf)
run = "pyclaims"
prefix = f"graspopt/{run}"
largest, smallest = f"{2**64 - 1:016x}", f"{0:016x}"


def token(key):
    return session.liveliness().declare_token(f"{prefix}/{key}")


def refused(hand_id):
    try:
        hand_agent.take_place(session, prefix, hand_id, lambda: None, wait_s=1.0)
    except SystemExit as e:
        return str(e)
    return "took the place"


# A hand with the id is alive: refused, naming its host.
alive = token("alive/hand/hostx/h1")
print("alive holder:", refused("h1"))
alive.undeclare()
# Only a settled claim is seen (the holder's liveliness not yet): refused all the same.
settled = token(f"claim/hand/h2/{largest}/settled")
print("settled claim:", refused("h2"))
settled.undeclare()
# Held, not settled yet: gives way to a settled claim with a larger number (the newcomer).
fresh = hand_agent.take_place(session, prefix, "h3", lambda: None)
other = token(f"claim/hand/h3/{largest}/settled")
time.sleep(0.3)
print("fresh vs settled larger:", fresh.lost)
# Settled (after SETTLE_AFTER_S): stays for a smaller number held, gives way to one settled.
old = hand_agent.take_place(session, prefix, "h4", lambda: None)
time.sleep(hand_agent.SETTLE_AFTER_S + 0.5)
phases = sorted(str(r.ok.key_expr).split("/")[-1]
                for r in session.liveliness().get(f"{prefix}/claim/hand/h4/**") if r.ok)
print("settled phases:", phases)
newcomer = token(f"claim/hand/h4/{smallest}/held")
time.sleep(0.3)
print("settled vs smaller held:", old.lost)
rival = token(f"claim/hand/h4/{smallest}/settled")
time.sleep(0.3)
print("settled vs smaller settled:", old.lost)
for held in (fresh, old):
    held.undeclare()
for declared in (other, newcomer, rival):
    declared.undeclare()
session.close()
