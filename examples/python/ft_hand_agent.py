#!/usr/bin/env python3
"""A graspopt hand with force/torque sensors in its fingertips, in Python (JSON on the wire).

It answers each trial command with a FingertipWrenches message (docs/protocol.md, "Writing a hand
with force sensors"): per touching fingertip, the sensor's pose, the fingertip surface, and the
force and torque the sensor read. The metric agent finds the contacts from the readings. Here the
readings come from a recording made by `graspopt record --sensing ft --hand barrett_ft`: each
command is answered with the readings of the recorded grasp nearest to its parameters. Replace
`read_sensors()` with your robot.

    pip install eclipse-zenoh~=1.10.0
    graspopt record --object mug --hand barrett_ft --sensing ft --steps 9 --out mug-ft.jsonl
    python3 ft_hand_agent.py --connect tcp/127.0.0.1:7447 --run mug --id py-ft-hand-1 \
        --recording mug-ft.jsonl

The bus side (taking the worker's place, liveliness, commands) is hand_agent.py's, imported from
beside this file. Only the Python standard library and eclipse-zenoh are needed.
"""

import time

import hand_agent


def check_grasp(grasp):
    """What keeps a recorded grasp from being answered as fingertip readings (None: nothing)."""
    if not isinstance(grasp, dict):
        return "not a JSON object"
    if not isinstance(grasp.get("fingertips"), list):
        return ("no fingertip readings (\"fingertips\"): record with "
                "`graspopt record --sensing ft --hand barrett_ft`")
    if not isinstance(grasp.get("params"), list):
        return "no parameters (\"params\")"
    return None


def read_sensors(grasps, command):
    """Executes `command` and reads the fingertip sensors: the palm pose reached, the readings
    (FingertipWrench dicts) and the smallest gap to the object if known, or an error.

    A robot driver plugs in here: move the palm to command["palm_pose"] (world frame), close the
    hand, then for each fingertip that touches, read its six-axis sensor and report
      {"finger": 0, "link": "finger_0_tip",
       "sensor_pose": {"translation": [x, y, z], "rotation": [w, x, y, z]},   # world frame
       "surface": {"shape": "sphere", "center": [0, 0, 0.015], "radius": 0.012},  # sensor frame
       "force": [fx, fy, fz],    # N: the force the object applies to the fingertip, sensor frame
       "torque": [tx, ty, tz],   # N m: its torque about the sensor's origin, sensor frame
       "stamp_ms": int(time.time() * 1000)}
    (negate force and torque if your sensor reports the wrench the fingertip applies). Here the
    readings are those of the recorded grasp nearest to the command's parameters.
    """
    grasp, error = hand_agent.measure(grasps, command)
    if error:
        return None, [], None, error
    return grasp["palm_pose"], grasp["fingertips"], grasp.get("min_gap"), None


def wrenches_of(grasps, command, worker):
    """The answer to `command`: the FingertipWrenches message, on the run's wrenches topic."""
    palm_pose, fingertips, min_gap, error = read_sensors(grasps, command)
    return "wrenches", {
        "wire": hand_agent.WIRE_VERSION,
        "run_id": command["run_id"],
        "trial_id": command["trial_id"],
        "attempt": command["attempt"],
        "worker": worker,
        "hand": command["hand"],
        "palm_pose": palm_pose if palm_pose is not None else command["palm_pose"],
        "fingertips": fingertips,
        "min_gap": min_gap,
        "error": error,
        "executed_ms": int(time.time() * 1000),
    }


def main():
    args = hand_agent.argument_parser(__doc__).parse_args()
    grasps = hand_agent.load_recording(args.recording, check_grasp)
    hand_agent.serve(args, grasps, wrenches_of, "wrenches")


if __name__ == "__main__":
    main()
