#!/usr/bin/env python3
"""Writes the hand-made seeds of tests/fuzz/corpus/ (the seedN files are random bytes kept from the first corpus) and
the hand-made reproducers of the fuzzer's findings (tests/fuzz/FINDINGS.md; fixed, so they are seeds too).

Each seed is a scene spelled in the byte language quathinge_fuzz.cpp decodes (class Input and the functions that
read from it, in the order they read): bodies, joints through each entry point, setters, the world, so the fuzzer
starts from deep, valid scenes and mutates them into bad ones. Regenerate after changing the decoder:
    python3 tests/fuzz/make_corpus.py
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


class Seed:
    def __init__(self):
        self.out = bytearray()

    # Input's primitives
    def byte(self, b):
        self.out.append(b & 0xFF)

    def flag(self, v):
        self.byte(1 if v else 0)

    def pick(self, i):
        self.byte(i)

    def raw(self, f):
        self.byte(0)  # mode < 16: a raw float follows
        self.out += struct.pack("<f", f)

    def value(self, v, lo, hi):
        if v == 0 and lo <= 0 <= hi:
            self.byte(16)  # mode 16..23: exactly 0
            return
        assert lo <= v <= hi, (v, lo, hi)
        self.byte(200)
        self.byte(round((v - lo) / (hi - lo) * 255))

    def vec(self, v, lo, hi):
        for c in v:
            self.value(c, lo, hi)

    def axis(self, name):
        """'x', 'y', 'z' or '-x', '-y', '-z': a coordinate axis (mode 16..63, mode % 3 = index, bit 8 = sign)."""
        index = "xyz".index(name[-1])
        negative = name.startswith("-")
        for mode in range(16, 64):
            if mode % 3 == index and bool(mode & 8) == negative:
                self.byte(mode)
                return

    def rotation(self, q=(0, 0, 0, 1)):
        for c in q:
            self.value(c, -1, 1)

    def frame(self, q=(0, 0, 0, 1), origin=(0, 0, 0)):
        self.byte(100)  # rigid (>= 16)
        self.rotation(q)
        self.vec(origin, -2, 2)

    # Scene pieces (makeBody, makeJoint, applySetter, checkJoint, the world)
    def body(self, mass, pos=(0, 0, 0), q=(0, 0, 0, 1), v=(0, 0, 0), w=(0, 0, 0), raw_w=None):
        if mass == 0:
            self.byte(0)
        else:
            self.byte(100)
            self.value(mass, 0.01, 100)
        self.rotation(q)
        self.vec(pos, -3, 3)
        self.vec(v, -20, 20)
        if raw_w is None:
            self.vec(w, -50, 50)
        else:
            for c in raw_w:
                self.raw(c)

    def setter(self, kind, *args):
        self.pick(kind)
        for write in args:
            write(self)


def V(v, lo, hi):
    return lambda s: s.value(v, lo, hi)


def F(v):
    return lambda s: s.flag(v)


def B(b):
    return lambda s: s.byte(b)


def check_bytes(s, reads):
    """checkJoint's reads for each joint: "rows+draw" (a joint without a fault: fps 60 and ERP 0.2 for the scratch
    rows, then the drawing size), "" (a faulted joint: nothing read)."""
    for r in reads:
        if "rows" in r:
            s.pick(0)
            s.byte(51)
        if "draw" in r:
            s.byte(38)


def world(s, joints, iterations=10, stabilize=False, dt_index=0, steps=6, between=None, reads=None, reads_after=None):
    """checkJoint's bytes, the world (iterations, stabilizer, dt = 1/60 s for index 0), the steps with a setter on the
    first joint before the steps listed in `between`, and checkJoint's bytes again."""
    reads = reads if reads is not None else ["rows+draw"] * joints
    reads_after = reads_after if reads_after is not None else reads
    check_bytes(s, reads)
    s.pick(iterations - 1)
    s.flag(stabilize)
    s.pick(dt_index)
    s.pick(steps - 1)
    for k in range(steps):
        if between and k in between:
            s.byte(0)
            s.pick(0)  # the first joint
            between[k](s)
        else:
            s.byte(255)
    check_bytes(s, reads_after)


def pendulum():
    s = Seed()
    s.body(1, pos=(0.5, 0, 0))
    s.body(0)
    s.body(0)
    s.byte(200)  # one joint
    s.byte(0)  # to the world
    s.flag(False)
    s.pick(1)
    s.vec((-0.5, 0, 0), -2, 2)
    s.axis("z")
    s.pick(0)  # no setters
    s.byte(255)  # no round trip
    world(s, 1)
    return s


def chain_limit_motor():
    s = Seed()
    s.body(1, pos=(0.5, 0, 0))
    s.body(1, pos=(1.5, 0, 0))
    s.body(1, pos=(2.5, 0, 0))
    s.byte(0)  # two joints
    # A–B, pivots and axes, a limit
    s.byte(200)
    s.flag(False)
    s.pick(0)
    s.vec((0.5, 0, 0), -2, 2)
    s.vec((-0.5, 0, 0), -2, 2)
    s.axis("z")
    s.axis("z")
    s.pick(1)
    s.setter(0, V(-0.5, -20, 20), V(0.5, -20, 20), V(0.9, 0, 1), V(0.3, 0, 1), V(1, 0, 1))
    s.byte(255)
    # C–B, frames, a motor
    s.byte(200)
    s.flag(True)
    s.pick(2)
    s.frame(origin=(-0.5, 0, 0))
    s.frame(origin=(0.5, 0, 0))
    s.pick(1)
    s.setter(1, F(True), V(2, -50, 50), V(1, -1, 10))
    s.byte(255)
    world(s, 2, steps=6)
    return s


def settings_servo_across_pi():
    s = Seed()
    s.body(1, pos=(0, -1, 0), w=(0, 0, 5))
    s.body(0)
    s.body(0)
    s.byte(200)
    s.byte(0)  # to the world's fixed body
    s.flag(False)
    s.pick(4)
    s.frame(origin=(0, 1, 0))
    s.frame()
    s.flag(False)  # useReferenceFrameA
    s.byte(255)  # not angular-only
    s.flag(True)  # useFrameOffset
    s.flag(True)  # hasLimit
    s.value(2.5, -20, 20)
    s.value(4, -20, 20)  # across +π
    s.value(0.9, 0, 1)
    s.value(0.3, 0, 1)
    s.value(1, 0, 1)
    s.pick(3)  # driveMode 2: servo
    s.value(0, -50, 50)
    s.value(0, -1, 10)
    s.value(3, -20, 20)
    s.value(5, -1, 50)
    s.value(20, -1, 100)
    s.value(0, -5, 5)
    s.value(1, -1, 30)
    s.value(1, -1, 3)
    s.value(0.1, -1, 10)  # friction
    for i in range(6):
        s.value(0.5, -0.5, 1.5)
        s.value(0.01, -0.5, 1.5)
    s.value(0.8, -0.5, 1.5)
    s.value(0.02, -0.5, 1.5)
    # flags: STOP_CFM | STOP_ERP | CFM_NORM | ERP_NORM and the per-row bits of rows 3 and 4 (ERP) and 0 (CFM)
    flags = 1 | 2 | 4 | 8 | (16 << 3) | (16 << 4) | (16 << 6)
    s.byte(flags & 0xFF)
    s.byte(flags >> 8)
    s.byte(255)
    s.pick(0)
    s.byte(255)
    world(s, 1, steps=6)
    return s


def stock_conversion():
    s = Seed()
    s.body(1, pos=(0, 0, 0))
    s.body(1, pos=(0, -1, 0))
    s.body(0)
    s.byte(200)
    s.byte(200)  # A–B
    s.flag(False)
    s.pick(5)
    s.vec((0, -0.5, 0), -2, 2)
    s.vec((0, 0.5, 0), -2, 2)
    s.axis("x")
    s.axis("x")
    s.flag(True)
    s.value(-1, -4, 4)
    s.value(1, -4, 4)
    s.value(0.9, -1, 2)
    s.value(0.3, -1, 2)
    s.value(1, -1, 2)
    s.flag(True)
    s.flag(True)
    s.value(-3, -50, 50)
    s.value(0.5, -1, 10)
    s.pick(2)
    s.pick(0)  # ERP
    s.flag(True)
    s.value(0.5, -0.5, 1.5)
    s.pick(1)  # STOP_ERP
    s.flag(False)
    s.value(0.7, -0.5, 1.5)
    s.byte(255)  # not angular-only
    s.pick(0)
    s.byte(255)
    world(s, 1)
    return s


def spring_friction_stabilized():
    s = Seed()
    s.body(2, pos=(1, 0, 0), w=(0, 0, 20))
    s.body(1, pos=(0, 0, 0))
    s.body(1, pos=(-1, 0, 0))
    s.byte(0)  # two joints
    s.byte(200)
    s.flag(False)
    s.pick(0)
    s.vec((-0.5, 0, 0), -2, 2)
    s.vec((0.5, 0, 0), -2, 2)
    s.axis("z")
    s.axis("z")
    s.pick(2)
    s.setter(3, V(1, -5, 5), V(4, -1, 30), V(0.5, -1, 3))
    s.setter(4, V(0.2, -1, 10))
    s.byte(255)
    s.byte(200)
    s.flag(False)
    s.pick(0)
    s.vec((0.5, 0, 0), -2, 2)
    s.vec((-0.5, 0, 0), -2, 2)
    s.axis("y")
    s.axis("y")
    s.pick(1)
    s.setter(6, B(0))  # angular-only
    s.byte(255)
    world(s, 2, stabilize=True, dt_index=1, steps=6)
    return s


def round_trip():
    s = Seed()
    s.body(1, pos=(0, 0, 0))
    s.body(1, pos=(0, 0, 1))
    s.body(0)
    s.byte(200)
    s.byte(200)
    s.flag(False)
    s.pick(0)
    s.vec((0, 0, 0.5), -2, 2)
    s.vec((0, 0, -0.5), -2, 2)
    s.axis("y")
    s.axis("y")
    s.pick(2)
    s.setter(0, V(-7, -20, 20), V(9, -20, 20), V(0.7, 0, 1), V(0.2, 0, 1), V(0.4, 0, 1))
    s.setter(2, V(1, -20, 20), V(2, -1, 50), V(10, -1, 100))
    s.byte(0)  # round trip
    s.pick(1)  # one overwrite
    s.byte(0)
    s.byte(200)  # at byte 200
    s.pick(0)  # 1 byte
    s.byte(0x3F)
    world(s, 1)
    return s


def nan_body_then_clear():
    s = Seed()
    s.body(1, pos=(0, 0, 0))
    s.body(1, pos=(0, -1, 0), raw_w=(float("nan"), 0, 0))
    s.body(1, pos=(0, -2, 0))
    s.byte(0)  # two joints: A–B (B is NaN), C–B
    for sign in (1, -1):
        s.byte(200)
        s.flag(False)
        s.pick(0)
        s.vec((0, -0.5 * sign, 0), -2, 2)
        s.vec((0, 0.5 * sign, 0), -2, 2)
        s.axis("z")
        s.axis("z")
        s.pick(0)
        s.byte(255)
    world(s, 2, steps=4, between={2: lambda t: t.setter(17, F(True))}, reads=["", ""])
    return s


def static_pair_frame_edits():
    s = Seed()
    s.body(0, pos=(0, 0, 0))
    s.body(0, pos=(0, 1, 0))
    s.body(0)
    s.byte(200)
    s.byte(200)
    s.flag(True)
    s.pick(2)
    s.frame(origin=(0, 0.5, 0))
    s.frame(q=(0, 0, 0.7071, 0.7071), origin=(0, -0.5, 0))
    s.pick(3)
    s.setter(16, F(True), B(1), lambda t: t.rotation((0.7071, 0, 0, 0.7071)))  # rigid edit of frame A
    s.setter(17, F(False))
    s.setter(11, B(5), V(0, -0.002, 0.002))  # setMultiTurnAngle(angle + 2π)
    s.byte(255)
    world(s, 1, steps=3, reads=[""])
    return s


def flipped_start():
    s = Seed()
    s.body(1, pos=(0, 0, 0))
    s.body(1, pos=(0, -1, 0), q=(1, 0, 0, 0))  # turned 180° about x: B's axis antiparallel to A's
    s.body(0)
    s.byte(200)
    s.byte(200)
    s.flag(False)
    s.pick(0)
    s.vec((0, -0.5, 0), -2, 2)
    s.vec((0, -0.5, 0), -2, 2)  # B's (0, -0.5, 0) is at A's pivot once turned
    s.axis("z")
    s.axis("z")
    s.pick(1)
    s.setter(0, V(-1, -20, 20), V(1, -20, 20), V(1, 0, 1), V(0.3, 0, 1), V(1, 0, 1))
    s.byte(255)
    world(s, 1, iterations=20, steps=6)
    return s


def setters_between_steps():
    s = Seed()
    s.body(1, pos=(0.5, 0, 0), w=(0, 0, 3))
    s.body(1, pos=(1.5, 0, 0))
    s.body(0)
    s.byte(200)
    s.byte(200)
    s.flag(False)
    s.pick(0)
    s.vec((0.5, 0, 0), -2, 2)
    s.vec((-0.5, 0, 0), -2, 2)
    s.axis("z")
    s.axis("z")
    s.pick(0)
    s.byte(255)
    world(
        s,
        1,
        steps=6,
        between={
            0: lambda t: t.setter(2, V(3, -20, 20), V(2, -1, 50), V(5, -1, 100)),
            1: lambda t: t.setter(5, B(2), V(0.1, -0.5, 1.5), B(4)),  # CFM on row kind 3
            2: lambda t: t.setter(10, lambda u: u.axis("y")),
            3: lambda t: t.setter(15, F(True), F(True)),
            4: lambda t: t.setter(3, V(-1, -5, 5), V(2, -1, 30), V(1, -1, 3)),
            5: lambda t: t.setter(19, B(0), B(0)),
        },
    )
    return s


# Reproducers of the findings listed in FINDINGS.md (float build). Each aborted the fuzz target until its bug was
# fixed; now they guard the fixes from the corpus.


def repro_debugdraw_half_open_limit():
    s = Seed()
    s.body(1, pos=(0.5, 0, 0))
    s.body(0)
    s.body(0)
    s.byte(200)
    s.byte(0)
    s.flag(False)
    s.pick(1)
    s.vec((-0.5, 0, 0), -2, 2)
    s.axis("z")
    s.pick(1)
    s.setter(0, lambda t: t.raw(float("-inf")), V(1, -20, 20), V(0.9, 0, 1), V(0.3, 0, 1), V(1, 0, 1))
    s.byte(255)
    world(s, 1)
    return s


def deserialize_repro(at, value):
    """A joint round-tripped through its QuatHinge chunk (btQuaternionHingeChunkData) with the bytes at `at`
    overwritten by `value`."""
    s = Seed()
    s.body(1, pos=(0.5, 0, 0))
    s.body(0)
    s.body(0)
    s.byte(200)
    s.byte(0)
    s.flag(False)
    s.pick(1)
    s.vec((-0.5, 0, 0), -2, 2)
    s.axis("z")
    s.pick(0)
    s.byte(0)  # round trip
    s.pick(1)  # one overwrite:
    s.byte(at >> 8)
    s.byte(at & 0xFF)
    s.pick({4: 2, 8: 3}[len(value)])  # 4 or 8 bytes
    for b in value:
        s.byte(b)
    world(s, 1)
    return s


def repro_deserialize_negative_breaking_threshold():
    return deserialize_repro(552, struct.pack("<d", -1e20))  # m_breakingImpulseThreshold (double, offset 552)


def repro_deserialize_huge_solver_iterations():
    return deserialize_repro(56, struct.pack("<i", 250000000))  # m_overrideNumSolverIterations (int, offset 56)


def pendulum_with_world_pivot_edited(y, stabilize, between):
    """One body hinged to the world; before the world, the world-side frame's pivot is edited (through
    getFrameOffsetB()) to y, which the next getInfo1 refuses (fault BT_QHINGE_FAULT_FRAME_EDITED_INVALID)."""
    s = Seed()
    s.body(1, pos=(0.5, 0, 0))
    s.body(0)
    s.body(0)
    s.byte(200)
    s.byte(0)
    s.flag(False)
    s.pick(1)
    s.vec((-0.5, 0, 0), -2, 2)
    s.axis("z")
    s.pick(1)
    s.setter(16, F(False), B(0), lambda t: (t.value(0, -2, 2), t.raw(y), t.value(0, -2, 2)))
    s.byte(255)
    world(s, 1, stabilize=stabilize, steps=3, between=between, reads=[""])
    return s


def repro_clearfault_keeps_invalid_edited_frame():
    return pendulum_with_world_pivot_edited(3e37, False, {0: lambda t: t.setter(17, F(True))})


def repro_stabilizer_projects_faulted_joint():
    return pendulum_with_world_pivot_edited(3e37, True, {0: lambda t: t.setter(18, F(True), B(255))})


def repro_constructor_nearly_antiparallel_axes():
    s = Seed()
    s.body(1, pos=(0, 0, 0))
    s.body(1, pos=(0, 1, 0))
    s.body(0)
    s.byte(200)
    s.byte(200)
    s.flag(False)
    s.pick(0)
    s.vec((0, 0.5, 0), -2, 2)
    s.vec((0, -0.5, 0), -2, 2)
    for axis in ((0.384335816, 0.509100378, 0.770131648), (-0.384335876, -0.509100437, -0.770131707)):
        s.byte(0)  # a raw axis
        for c in axis:
            s.out += struct.pack("<f", c)
    s.pick(0)
    s.byte(255)
    world(s, 1)
    return s


REPRODUCERS = {
    "clearfault-keeps-invalid-edited-frame": repro_clearfault_keeps_invalid_edited_frame,
    "stabilizer-projects-faulted-joint": repro_stabilizer_projects_faulted_joint,
    "constructor-nearly-antiparallel-axes": repro_constructor_nearly_antiparallel_axes,
    "debugdraw-half-open-limit": repro_debugdraw_half_open_limit,
    "deserialize-negative-breaking-threshold": repro_deserialize_negative_breaking_threshold,
    "deserialize-huge-solver-iterations": repro_deserialize_huge_solver_iterations,
}

SEEDS = {
    "pendulum": pendulum,
    "chain_limit_motor": chain_limit_motor,
    "settings_servo_across_pi": settings_servo_across_pi,
    "stock_conversion": stock_conversion,
    "spring_friction_stabilized": spring_friction_stabilized,
    "round_trip": round_trip,
    "nan_body_then_clear": nan_body_then_clear,
    "static_pair_frame_edits": static_pair_frame_edits,
    "flipped_start": flipped_start,
    "setters_between_steps": setters_between_steps,
}

if __name__ == "__main__":
    for folder, table in (("corpus", SEEDS), ("corpus", REPRODUCERS)):
        os.makedirs(os.path.join(HERE, folder), exist_ok=True)
        for name, make in table.items():
            data = bytes(make().out)
            with open(os.path.join(HERE, folder, name), "wb") as f:
                f.write(data)
            print(f"{folder}/{name}: {len(data)} bytes")
