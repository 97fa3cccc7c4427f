"""The bindings: bodies, shapes, joints, portals, queries, events, bulk
arrays, snapshots and pickling, typed errors."""

import copy
import math
import pickle

import numpy as np
import pytest

import janus2d
from janus2d import errors

DT = 1.0 / 60.0


def ground_and_ball(y=5.0):
    world = janus2d.World()
    ground = world.create_body("static", (0.0, -0.5))
    world.create_box(ground, 20.0, 0.5)
    ball = world.create_body("dynamic", (0.0, y))
    world.create_circle(ball, 0.5)
    return world, ground, ball


def test_free_fall_matches_gravity():
    world = janus2d.World()
    body = world.create_body("dynamic", (0.0, 100.0))
    world.create_box(body, 0.5, 0.5)
    world.step(DT, steps=60)
    vx, vy = world.linear_velocity(body)
    assert vx == 0.0
    assert vy == pytest.approx(-10.0, abs=1e-3)
    # Semi-implicit Euler over 4 substeps of h = dt/4 each step:
    # drop = g h^2 (1 + 2 + ... + 240) = 5.0208 m.
    h = DT / 4
    assert 100.0 - world.position(body)[1] == pytest.approx(10 * h * h * 240 * 241 / 2, abs=1e-3)
    assert world.step_count == 60


def test_ball_comes_to_rest_on_the_ground():
    world, _, ball = ground_and_ball()
    world.step(DT, steps=240)
    assert world.position(ball)[1] == pytest.approx(0.5, abs=0.01)
    assert world.contact_count(ball) == 1
    assert not world.is_awake(ball)


def test_defaults_are_the_rust_defaults():
    body = janus2d.defaults("body")
    assert body["gravity_scale"] == 1.0 and body["linear_damping"] == 0.0
    assert body["enable_sleep"] is True and body["sleep_threshold"] is None
    shape = janus2d.defaults("shape")
    assert shape["density"] == 1.0 and shape["mask_bits"] == 2**64 - 1
    world = janus2d.defaults("world")
    assert world["gravity"] == (0.0, -10.0) and world["substeps"] == 4
    rev = janus2d.defaults("revolute")
    assert rev["enable_motor"] is False and math.isinf(rev["force_threshold"])
    with pytest.raises(ValueError):
        janus2d.defaults("nope")
    # A body made with no keywords has those defaults.
    w = janus2d.World()
    b = w.create_body()
    w.create_circle(b, 1.0)
    assert w.mass(b) == pytest.approx(math.pi, rel=1e-5)  # density 1, r = 1


def test_keywords_reach_the_definitions():
    world = janus2d.World(gravity=(0.0, 0.0))
    b = world.create_body("dynamic", (1.0, 2.0), angle=0.5, linear_velocity=(3.0, 0.0),
                          user_data=42)
    world.create_box(b, 0.5, 0.5, density=4.0)
    assert world.angle(b) == pytest.approx(0.5)
    assert world.body_user_data(b) == 42
    assert world.mass(b) == pytest.approx(4.0, rel=1e-5)
    world.step(0.5)
    assert world.position(b)[0] == pytest.approx(2.5, abs=1e-4)
    with pytest.raises(TypeError, match="no_such_field"):
        world.create_body("dynamic", no_such_field=1)
    with pytest.raises(TypeError):
        world.create_box(b, 1.0, 1.0, densty=2.0)
    fixed = world.create_body("dynamic", mass=2.0, rotational_inertia=0.5)
    assert world.mass(fixed) == 2.0 and world.rotational_inertia(fixed) == 0.5


def test_impulse_changes_momentum_by_the_impulse():
    world = janus2d.World(gravity=(0.0, 0.0))
    b = world.create_body("dynamic")
    world.create_box(b, 1.0, 0.5, density=2.0)
    m = world.mass(b)
    world.apply_linear_impulse(b, (3.0, -1.0))
    vx, vy = world.linear_velocity(b)
    assert (m * vx, m * vy) == (pytest.approx(3.0, rel=1e-5), pytest.approx(-1.0, rel=1e-5))


def test_bulk_state_round_trip():
    world = janus2d.World(gravity=(0.0, 0.0))
    bodies = [world.create_body("dynamic", (float(i), 0.0)) for i in range(5)]
    for b in bodies:
        world.create_circle(b, 0.25)
    state = world.get_state(bodies)
    assert state.shape == (5, 6) and state.dtype == np.float64
    assert np.array_equal(state[:, 0], np.arange(5.0))
    new = np.zeros((5, 6))
    new[:, 0] = np.arange(5) * 10.0
    new[:, 1] = 1.0
    new[:, 2] = 0.25
    new[:, 3] = 2.0
    new[:, 5] = -1.0
    world.set_state(bodies, new)
    assert np.allclose(world.get_state(bodies), new, atol=1e-6)
    assert np.allclose(world.get_positions(bodies), new[:, :2])
    assert np.allclose(world.get_angles(bodies), 0.25)
    world.set_velocities(bodies, np.tile([0.0, 1.0, 0.0], (5, 1)))
    world.step(1.0)
    assert np.allclose(world.get_positions(bodies)[:, 1], 2.0, atol=1e-5)
    with pytest.raises(ValueError, match="shape"):
        world.set_state(bodies, np.zeros((4, 6)))
    # A NaN anywhere: nothing changes.
    before = world.get_state(bodies)
    bad = before.copy()
    bad[3, 1] = np.nan
    with pytest.raises(errors.InvalidInputError):
        world.set_state(bodies, bad)
    assert np.array_equal(world.get_state(bodies), before)
    with pytest.raises(TypeError):
        world.get_state([1, 2])


def test_errors_are_typed():
    world, ground, ball = ground_and_ball()
    with pytest.raises(errors.InvalidInputError) as e:
        world.step(0.0)
    assert e.value.kind == "InvalidTimeStep"
    with pytest.raises(errors.InvalidInputError) as e:
        world.create_circle(ball, -1.0)
    assert e.value.kind == "Geometry"
    with pytest.raises(errors.InvalidInputError):
        world.set_linear_velocity(ball, (float("nan"), 0.0))
    with pytest.raises(errors.BodyTypeError):
        world.apply_linear_impulse(ground, (1.0, 0.0))
    other = janus2d.World()
    with pytest.raises(errors.ForeignHandleError):
        other.position(ball)
    world.destroy_body(ball)
    with pytest.raises(errors.StaleHandleError) as e:
        world.position(ball)
    assert e.value.kind == "StaleBody"
    assert isinstance(e.value, LookupError) and isinstance(e.value, errors.Janus2dError)
    a = world.create_body("dynamic", (0.0, 3.0))
    j = world.create_weld_joint(ground, a, (0.0, 3.0))
    with pytest.raises(errors.WrongJointKindError):
        world.set_joint_motor_speed(j, 1.0)
    with pytest.raises(errors.InvalidInputError):
        world.create_revolute_joint(a, a, (0.0, 0.0))
    with pytest.raises(ValueError):
        world.create_body("floating")


def test_revolute_motor_turns_at_its_speed():
    world = janus2d.World(gravity=(0.0, 0.0))
    ground = world.create_body("static")
    wheel = world.create_body("dynamic")
    world.create_circle(wheel, 0.5)
    j = world.create_revolute_joint(ground, wheel, (0.0, 0.0), enable_motor=True,
                                    motor_speed=2.0, max_motor_torque=100.0)
    world.step(DT, steps=30)
    assert world.angular_velocity(wheel) == pytest.approx(2.0, abs=1e-3)
    assert world.joint_angle(j) == pytest.approx(1.0, abs=0.05)
    assert world.joint_kind(j) == "revolute"
    world.set_joint_motor_speed(j, -1.0)
    world.step(DT)
    assert world.angular_velocity(wheel) == pytest.approx(-1.0, abs=1e-3)


def test_pendulum_keeps_its_length():
    world = janus2d.World()
    ground = world.create_body("static")
    bob = world.create_body("dynamic", (2.0, 0.0))
    world.create_circle(bob, 0.1)
    world.create_distance_joint(ground, bob, (0.0, 0.0), (2.0, 0.0))
    # Half a period, pi sqrt(L / g) = 1.405 s: the bob is at the far side.
    world.step(DT, steps=84)
    x, y = world.position(bob)
    assert math.hypot(x, y) == pytest.approx(2.0, abs=0.01)
    assert x < -1.8


def test_every_joint_kind_is_created():
    world = janus2d.World()
    g = world.create_body("static")
    bodies = [world.create_body("dynamic", (float(i), 1.0)) for i in range(8)]
    for b in bodies:
        world.create_box(b, 0.2, 0.2)
    joints = [
        world.create_revolute_joint(g, bodies[0], (0.0, 1.0)),
        world.create_prismatic_joint(g, bodies[1], (1.0, 1.0), axis=(1.0, 0.0)),
        world.create_weld_joint(g, bodies[2], (2.0, 1.0)),
        world.create_distance_joint(g, bodies[3], (3.0, 2.0), (3.0, 1.0)),
        world.create_wheel_joint(g, bodies[4], (4.0, 1.0)),
        world.create_motor_joint(g, bodies[5], max_force=10.0),
        world.create_mouse_joint(g, bodies[6], (6.0, 1.0), 100.0),
        world.create_filter_joint(g, bodies[7]),
    ]
    kinds = [world.joint_kind(j) for j in joints]
    assert kinds == ["revolute", "prismatic", "weld", "distance", "wheel", "motor",
                     "mouse", "filter"]
    assert world.joint_count == 8
    world.step(DT, steps=10)
    # The weld holds its body where it was.
    assert world.position(bodies[2]) == pytest.approx((2.0, 1.0), abs=1e-3)
    # The prismatic slide keeps y.
    assert world.position(bodies[1])[1] == pytest.approx(1.0, abs=1e-3)


def test_queries():
    world, ground, ball = ground_and_ball(y=3.0)
    hit = world.cast_ray((0.0, 10.0), (0.0, -20.0))
    assert hit["body"] == ball
    assert hit["point"][1] == pytest.approx(3.5, abs=1e-4)
    assert hit["normal"] == pytest.approx((0.0, 1.0), abs=1e-5)
    hit = world.cast_ray((0.0, 10.0), (0.0, -20.0), exclude=ball)
    assert hit["body"] == ground
    assert world.cast_ray((0.0, 10.0), (0.0, 1.0)) is None
    assert [b for _, b in world.overlap_point((0.0, 3.2))] == [ball]
    found = {b for _, b in world.overlap_aabb((-1.0, -1.0), (1.0, 4.0))}
    assert found == {ball, ground}
    with pytest.raises(errors.InvalidInputError):
        world.cast_ray((0.0, 0.0), (0.0, 0.0))


def test_events_report_contacts_and_sensors():
    world, ground, ball = ground_and_ball(y=1.0)
    sensor_body = world.create_body("static", (0.0, 0.3))
    sensor = world.create_box(sensor_body, 0.2, 0.2, is_sensor=True)
    shapes = world.body_shapes(ball)
    began, sensed = [], []
    for _ in range(60):
        world.step(DT)
        ev = world.events()
        began += ev["contact_begin"]
        sensed += ev["sensor_begin"]
    assert any(shapes[0] in pair for pair in began)
    assert any(sensor in pair for pair in sensed)


def test_snapshot_bytes_restore_bit_for_bit():
    world, _, ball = ground_and_ball()
    world.step(DT, steps=10)
    saved = world.to_bytes()
    assert saved[:4] == b"JNS2"
    world.step(DT, steps=30)
    after = world.state_hash()
    world.restore(saved)
    world.step(DT, steps=30)
    assert world.state_hash() == after
    # A world from the bytes continues the same way, and the handles work.
    other = janus2d.World.from_bytes(saved)
    other.step(DT, steps=30)
    assert other.state_hash() == after
    assert other.position(ball) == world.position(ball)


def test_pickle_and_copy():
    world, _, ball = ground_and_ball()
    world.step(DT, steps=5)
    clone = pickle.loads(pickle.dumps(world))
    twin = copy.deepcopy(world)
    for w in (world, clone, twin):
        w.step(DT, steps=20)
    assert clone.state_hash() == world.state_hash() == twin.state_hash()
    assert pickle.loads(pickle.dumps(ball)) == ball
    assert hash(pickle.loads(pickle.dumps(ball))) == hash(ball)


def test_bad_snapshot_bytes_raise():
    world, _, _ = ground_and_ball()
    data = bytearray(world.to_bytes())
    with pytest.raises(errors.SnapshotError) as e:
        janus2d.World.from_bytes(bytes(data[:10]))
    assert e.value.kind == "Truncated"
    data[-1] ^= 0xFF
    with pytest.raises(errors.SnapshotError) as e:
        janus2d.World.from_bytes(bytes(data))
    assert e.value.kind == "Checksum"
    with pytest.raises(errors.SnapshotError) as e:
        janus2d.World.from_bytes(b"NOPE" + bytes(40))
    assert e.value.kind == "BadMagic"


def test_portal_carries_a_box_from_floor_to_wall():
    world = janus2d.World()
    floor = world.create_body("static", (0.0, -0.5))
    world.create_box(floor, 5.0, 0.5)
    wall = world.create_body("static", (20.0, 5.0))
    world.create_box(wall, 0.5, 5.0)
    pair = world.create_portal_pair(floor, (0.0, 0.5), (0.0, 1.0), 1.0,
                                    wall, (-0.5, 0.0), (-1.0, 0.0), 1.0)
    box = world.create_body("dynamic", (0.0, 2.0))
    world.create_box(box, 0.3, 0.3)
    kinds = set()
    for _ in range(120):
        world.step(DT)
        kinds |= {e["type"] for e in world.portal_events()}
    assert {"crossing_started", "crossing_completed"} <= kinds
    # Out of the wall's left face, moving left.
    x, y = world.position(box)
    assert x < 19.5 and world.linear_velocity(box)[0] < 0.0
    world.destroy_portal_pair(pair)
    with pytest.raises(errors.StaleHandleError):
        world.destroy_portal_pair(pair)
    with pytest.raises(errors.InvalidInputError):
        world.create_portal_pair(floor, (0.0, 0.5), (0.0, 0.0), 1.0,
                                 wall, (-0.5, 0.0), (-1.0, 0.0), 1.0)


def test_render_draws_something():
    world, _, _ = ground_and_ball()
    img = world.render(120, 80)
    assert img.shape == (80, 120, 3) and img.dtype == np.uint8
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 2
    with pytest.raises(ValueError):
        world.render(0, 10)
    with pytest.raises(ValueError):
        world.render(10, 10, center=(0.0, 0.0))
