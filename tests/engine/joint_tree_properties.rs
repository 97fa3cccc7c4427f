//! Property tests of the direct joint-tree solve
//! (`janus2d_constraints::joint_tree`): on random trees of revolute joints
//! (2–10 dynamic bodies, each hinged to an earlier one or to a static pin,
//! some also pinned a second time; masses and inertias in [0.1, 1e3]) one
//! solve
//!
//! - satisfies every joint's soft row exactly: `J v' + b_v + Γ Δλ = 0`
//!   (with bias: `b_v` the velocity solve's share of `β C`, see
//!   `joint_tree::VELOCITY_CORRECTION_SPEED`) or `J v' + Γ Δλ = 0`
//!   (relax), `Γ = K / a2`;
//! - changes the bodies' total linear momentum by exactly the impulses the
//!   static pin takes.
//!
//! At least 256 cases each, f32 and f64. Bounds: the residual is
//! `8 n ε s (1 + a2)` of the size of the velocity terms, with `n` joints,
//! `s` the spread (max / min) of the bodies' masses and inertias and
//! `1 + a2` the softness's regularisation, which together bound the
//! system's condition (the elimination runs in f64 in both builds, so the
//! f32 build keeps a wide margin); momentum is `64 n ε` of the largest
//! `m (|v| + |Δv|)`, since every impulse is applied equal and opposite
//! through its joint. `JANUS2D_REPORT=1` prints the
//! worst error as a fraction of its bound.

use janus2d_constraints::joint_tree::{
    HEAVY_SPRING_FACTOR, VELOCITY_CORRECTION_SPEED, heavy_spring_inv_mass, spring_inv_mass,
};
use janus2d_constraints::revolute::{RevoluteJoint, RevoluteJointDef};
use janus2d_constraints::{Joint, JointForest};
use janus2d_core::body::{BodyHandle, BodySet, BodyType};
use janus2d_core::constraint::{Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::solver::SolverSettings;
use janus2d_testbed::support::*;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// One joint of a tree case: its parent (0 = the static pin, k = body k−1)
/// and its two local anchors.
#[derive(Clone, Debug)]
struct Link {
    parent: usize,
    anchor_parent: Vec2,
    anchor_child: Vec2,
}

#[derive(Clone, Debug)]
struct TreeCase {
    bodies: Vec<BodySpec>,
    links: Vec<Link>,
    /// Bodies hinged to the pin a second time (index, local anchor).
    extra_pins: Vec<(usize, Vec2)>,
    use_bias: bool,
}

fn tree_case() -> impl Strategy<Value = TreeCase> {
    (2usize..=10)
        .prop_flat_map(|n| {
            let body = body_spec(Just(BodyType::Dynamic))
                .prop_flat_map(|b| (Just(b), log_uniform(-1.0, 3.0), log_uniform(-1.0, 3.0)));
            let link = (0usize..1000, vec2(1.5), vec2(1.5));
            (
                prop::collection::vec(body, n),
                prop::collection::vec(link, n),
                prop::collection::vec((0usize..1000, vec2(1.5)), 0..3),
                any::<bool>(),
            )
        })
        .prop_map(|(bodies, links, extra, use_bias)| {
            let n = bodies.len();
            let bodies = bodies
                .into_iter()
                .map(|(mut b, m, i)| {
                    b.mass = m;
                    b.inertia = i;
                    b
                })
                .collect();
            let links = links
                .into_iter()
                .enumerate()
                .map(|(k, (p, anchor_parent, anchor_child))| Link {
                    parent: p % (k + 1),
                    anchor_parent,
                    anchor_child,
                })
                .collect();
            let extra_pins = extra.into_iter().map(|(i, a)| (i % n, a)).collect();
            TreeCase {
                bodies,
                links,
                extra_pins,
                use_bias,
            }
        })
}

/// The revolute joint inside a [`Joint`] (every joint here is one).
fn revolute(j: &Joint) -> &RevoluteJoint {
    j.as_revolute().expect("a revolute joint")
}

struct Built {
    set: BodySet,
    bodies: Vec<BodyHandle>,
    joints: Vec<Joint>,
    /// Per joint: true when body a is the static pin.
    pinned: Vec<bool>,
}

fn build(case: &TreeCase, ctx: &StepContext) -> Built {
    let mut set = BodySet::new();
    let pin = BodySpec::fixed(Vec2::new(0.5, -0.5), 0.3).create(&mut set);
    let bodies: Vec<BodyHandle> = case.bodies.iter().map(|b| b.create(&mut set)).collect();
    let mut joints = Vec::new();
    let mut pinned = Vec::new();
    for (k, link) in case.links.iter().enumerate() {
        let parent = if link.parent == 0 {
            pin
        } else {
            bodies[link.parent - 1]
        };
        let def = RevoluteJointDef::new(parent, bodies[k], link.anchor_parent, link.anchor_child);
        joints.push(Joint::from(RevoluteJoint::new(def)));
        pinned.push(link.parent == 0);
    }
    for &(i, anchor) in &case.extra_pins {
        let def = RevoluteJointDef::new(pin, bodies[i], Vec2::ZERO, anchor);
        joints.push(Joint::from(RevoluteJoint::new(def)));
        pinned.push(true);
    }
    for j in joints.iter_mut() {
        j.prepare(ctx, &set);
    }
    Built {
        set,
        bodies,
        joints,
        pinned,
    }
}

/// The `K` blocks of the joints (their rows before the solve) as their
/// trees' springs see them: every moving body at its tree's spring mass
/// where the tree is anchored (a joint with one moving body) and its
/// masses span more than `HEAVY_TREE_RATIO`
/// (`joint_tree::heavy_spring_inv_mass`, `spring_inv_mass`); each
/// joint's own `K` otherwise. A tree is a set of joints joined through
/// moving bodies (a static pin joins none).
///
/// Also returns the largest stiffening over the trees (a light body's own
/// inverse mass over its tree's spring inverse mass, at most
/// `HEAVY_SPRING_FACTOR`; 1 where no tree is heavy): the regularisation
/// `Γ` is that much smaller, the system's condition that much larger.
pub(super) fn spring_ks(before: &[ConstraintRows]) -> (Vec<[[f64; 3]; 3]>, f64) {
    let moving = |rows: &ConstraintRows| -> Vec<BodyHandle> {
        let mut bodies: Vec<BodyHandle> = rows
            .rows
            .iter()
            .flat_map(|row| row.jacobian.iter())
            .filter(|e| e.inv_mass > 0.0)
            .map(|e| e.body)
            .collect();
        bodies.sort_unstable();
        bodies.dedup();
        bodies
    };
    // Each joint's tree: joints sharing a moving body, merged until no
    // two trees share one.
    let bodies: Vec<Vec<BodyHandle>> = before.iter().map(moving).collect();
    let mut tree: Vec<usize> = (0..before.len()).collect();
    let mut changed = true;
    while changed {
        changed = false;
        for i in 0..before.len() {
            for j in 0..i {
                if tree[i] != tree[j] && bodies[i].iter().any(|b| bodies[j].contains(b)) {
                    let (keep, gone) = (tree[i].min(tree[j]), tree[i].max(tree[j]));
                    tree.iter_mut()
                        .filter(|t| **t == gone)
                        .for_each(|t| *t = keep);
                    changed = true;
                }
            }
        }
    }
    let mut stiffening: f64 = 1.0;
    let ks = before
        .iter()
        .enumerate()
        .map(|(i, rows)| {
            let members = || {
                before
                    .iter()
                    .zip(&bodies)
                    .zip(&tree)
                    .filter(|(_, t)| **t == tree[i])
            };
            // Held by a fixed end: a joint with one moving body.
            let anchored = members().any(|((_, b), _)| b.len() < 2);
            let heavy = if anchored {
                // (The tests' steps: 1/60 s in 4 substeps, the factor's own.)
                heavy_spring_inv_mass(
                    members()
                        .flat_map(|((r, _), _)| r.rows.iter().flat_map(|row| row.jacobian.iter()))
                        .map(|e| e.inv_mass),
                    HEAVY_SPRING_FACTOR,
                )
            } else {
                0.0
            };
            let mut seen = rows.clone();
            for e in seen.rows.iter_mut().flat_map(|row| row.jacobian.iter_mut()) {
                if heavy > 0.0 {
                    stiffening = stiffening.max(d(e.inv_mass / heavy));
                }
                (e.inv_mass, e.inv_inertia) = spring_inv_mass(e.inv_mass, e.inv_inertia, heavy);
            }
            let n = rows.blocks[0].len;
            let mut k = [[0.0; 3]; 3];
            for (i, k_i) in k.iter_mut().enumerate().take(n) {
                for (j, k_ij) in k_i.iter_mut().enumerate().take(n) {
                    *k_ij = d(seen.jmj(i, j));
                }
            }
            k
        })
        .collect();
    (ks, stiffening)
}

/// The longest lever arm squared (m²) over the joints' bodies: for each
/// body of a joint, the sum of its angular Jacobian entries squared over
/// the joint's two point rows, `(r × x̂)² + (r × ŷ)² = |r|²`.
pub(super) fn lever_squared(rows: &[ConstraintRows]) -> f64 {
    let mut longest: f64 = 0.0;
    for joint in rows {
        let mut arms: Vec<(BodyHandle, f64)> = Vec::new();
        for e in joint
            .rows
            .iter()
            .take(2)
            .flat_map(|row| row.jacobian.iter())
        {
            match arms.iter_mut().find(|(b, _)| *b == e.body) {
                Some((_, sum)) => *sum += d(e.angular * e.angular),
                None => arms.push((e.body, d(e.angular * e.angular))),
            }
        }
        longest = arms.iter().map(|(_, sum)| *sum).fold(longest, f64::max);
    }
    longest
}

/// The size of the velocity terms whose rounding enters a tree solve's
/// residual (m/s): the bodies' speeds (`|v| + 4 |ω|`), the first `rows`
/// rows' `J v` of each joint, and with a bias rate `β` (1/s) their `β C`.
pub(super) fn speed_scale(
    bodies: &[BodySpec],
    before: &[ConstraintRows],
    set: &BodySet,
    rows: usize,
    bias_rate: Option<Real>,
) -> f64 {
    let mut scale: f64 = bodies
        .iter()
        .map(|s| d(s.v.length()) + 4.0 * d(s.w.abs()))
        .fold(0.0, f64::max);
    for joint in before {
        for i in 0..rows {
            scale = scale.max(d(joint.row_velocity(i, |h| velocity(set, h))).abs());
            if let Some(rate) = bias_rate {
                scale = scale.max(d(rate * joint.rows[i].c).abs());
            }
        }
    }
    scale
}

/// One tree solve, measured ([`solve_measured`]).
pub(super) struct Measured {
    /// The direct joint softness's compliance `s_i / s_m` (the `Γ / K` of
    /// the soft rows' `Ċ + b + Γ λ = 0`).
    pub(super) compliance: f64,
    /// Each joint's rows before the solve.
    pub(super) before: Vec<ConstraintRows>,
    /// [`speed_scale`] of the rows before the solve, m/s.
    pub(super) scale: f64,
    /// Each joint's spring `K` and the trees' stiffening ([`spring_ks`]).
    pub(super) ks: Vec<[[f64; 3]; 3]>,
    pub(super) stiffening: f64,
}

/// One tree solve of `joints` over `set`, measured: the forest built (every
/// joint in a tree, or the case fails), each joint's rows, the speed scale
/// of their first `rows` rows and their spring `K`s taken before it.
pub(super) fn solve_measured(
    ctx: &StepContext,
    (joints, set): (&mut [Joint], &mut BodySet),
    bodies: &[BodySpec],
    rows: usize,
    use_bias: bool,
) -> Result<Measured, TestCaseError> {
    let mut forest = JointForest::default();
    forest.build(joints, &set.states, true);
    prop_assert_eq!(forest.tree_joint_count(), joints.len());
    let before: Vec<_> = joints.iter().map(|j| j.rows(ctx, set)).collect();
    let rate = ctx.direct_joint_softness.bias_rate;
    let scale = speed_scale(bodies, &before, set, rows, use_bias.then_some(rate));
    let (ks, stiffening) = spring_ks(&before);
    forest.solve(ctx, joints, &mut set.states, use_bias);
    let soft = ctx.direct_joint_softness;
    Ok(Measured {
        compliance: d(soft.impulse_scale / soft.mass_scale),
        before,
        scale,
        ks,
        stiffening,
    })
}

/// The bound on a tree solve's residual, `8 n ε s (1 + a2 stiffening)
/// (1 + r²) scale`: rounding in the elimination grows with the number of
/// joints `n`, the spread `s` of the bodies' masses and inertias (the
/// pivots' condition; kg and kg·m² mixed, lengths taken as metres), and
/// the longest lever arm squared `r²` (m², the rows' `K` mixes `m⁻¹` with
/// `r² I⁻¹`). The regularised system's condition is at most the spread
/// times `1 + a2`: `Γ = K / a2` keeps its smallest eigenvalue off zero; a
/// heavy tree's springs, `stiffening` times stiffer, keep it that much
/// less far off.
pub(super) fn residual_bound(
    bodies: &[BodySpec],
    joints: usize,
    stiffening: f64,
    lever_squared: f64,
    scale: f64,
) -> f64 {
    let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
    let soft = ctx.direct_joint_softness;
    let a2 = d(soft.mass_scale / soft.impulse_scale);
    let (lo, hi) = bodies
        .iter()
        .flat_map(|b| [d(b.mass), d(b.inertia)])
        .fold((f64::MAX, 0.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    8.0 * joints as f64 * EPS * (hi / lo) * (1.0 + a2 * stiffening) * (1.0 + lever_squared) * scale
}

pub(super) fn velocity(set: &BodySet, h: BodyHandle) -> (Vec2, Real) {
    let s = set.solver_body(h).state;
    (s.v, s.w)
}

/// One solve satisfies every joint's two soft point rows exactly:
/// `J v' + b + Γ λ' = 0` (bias) or `J v' + Γ Δλ = 0` (relax), `Γ = K / a2`
/// on the tree's spring masses (`spring_ks`).
#[test]
fn tree_solve_satisfies_every_soft_row() {
    check("tree solve residual", tree_case(), |case| {
        let (worst, bound) = tree_residual(&case)?;
        prop_assert!(worst <= bound, "residual {worst:e} > {bound:e}");
        Ok(worst / bound)
    });
}

/// Known limit, kept as a regression case: a tree closed into a loop
/// through the ground (a heavy body pinned at its centre, a light body
/// hinged to it, a second light body hinged to that one off its centre and
/// pinned too; springs built on the heavy mass). The elimination folds the
/// stiff pin rows into the bodies' pivots without pivoting, so the loop's
/// one free motion is resolved from differences of pivots about 10⁴ times
/// larger: in the f64 build the two loop joints' residual is 3.2e-5
/// against a bound of 2.8e-6 (their impulses differ from a dense
/// partial-pivoting solve of the same rows, residual 6.7e-16, by 1.3e-5
/// of their size). One case in about 600,000 of the property test's
/// random trees is of this kind.
#[test]
#[ignore = "known: a tree closed through the ground loses precision (residual 3.2e-5 > 2.8e-6, f64)"]
fn tree_residual_of_a_loop_closed_through_the_ground() {
    // The figures as the f64 run printed them (rounded to f32 in that
    // build, where the case is not the same).
    let masses: [f64; 9] = [
        8.296_857_428_396_388,
        25.211_626_644_395_817,
        143.530_253_446_938_42,
        206.704_079_669_980_9,
        330.479_716_264_371_35,
        4.453_608_089_868_529_5,
        1.0,
        1.0,
        1.0,
    ];
    let v = |x: f64, y: f64| Vec2::new(x as Real, y as Real);
    let mut bodies: Vec<BodySpec> = masses
        .iter()
        .map(|m| BodySpec::dynamic(Vec2::ZERO, *m as Real, 1.0))
        .collect();
    bodies[6].angle = -2.586_523_428_366_732_f64 as Real;
    bodies[6].w = -1.297_626_931_421_639_f64 as Real;
    let link = |parent, anchor_parent| Link {
        parent,
        anchor_parent,
        anchor_child: Vec2::ZERO,
    };
    let z = Vec2::ZERO;
    let case = TreeCase {
        bodies,
        links: vec![
            link(0, z),
            link(0, z),
            link(0, z),
            link(3, z),
            link(0, z),
            link(3, z),
            link(3, z),
            link(7, v(-0.759_995_379_990_794_3, -0.621_165_954_240_74)),
            link(0, z),
        ],
        extra_pins: vec![(7, v(-0.821_080_700_299_547_7, 0.388_126_156_820_610_8))],
        use_bias: false,
    };
    let (worst, bound) = tree_residual(&case).unwrap();
    assert!(worst <= bound, "residual {worst:e} > {bound:e}");
}

/// A case the property test met in the f64 build (shrunk; the figures
/// below are that build's): a body pinned
/// at its centre, a lighter one hinged to it and pinned a second time
/// 1.4 m off its centre, so four rows hold its three degrees of freedom.
/// Its residual, 3.3e-11, exceeded the bound (3.2e-11) until the bound
/// took the lever arm in (see `tree_residual`).
#[test]
fn tree_residual_of_a_second_pin_off_the_centre() {
    // The figures as the f64 run printed them (rounded to f32 in that
    // build, where the case is not the same); rounded to seven digits the
    // f64 case passed without the lever arm too.
    let v = |x: f64, y: f64| Vec2::new(x as Real, y as Real);
    let mut light = BodySpec::dynamic(Vec2::ZERO, 1.0, 1.747_021_002_237_331_f64 as Real);
    light.w = -0.044_020_958_143_869_99_f64 as Real;
    let at_centre = |parent| Link {
        parent,
        anchor_parent: Vec2::ZERO,
        anchor_child: Vec2::ZERO,
    };
    let heavy = BodySpec::dynamic(Vec2::ZERO, 12.365_637_178_043_766_f64 as Real, 1.0);
    let case = TreeCase {
        bodies: vec![heavy, light],
        links: vec![at_centre(0), at_centre(1)],
        extra_pins: vec![(1, v(-0.696_386_018_335_103_5, -1.225_805_181_892_191))],
        use_bias: false,
    };
    let (worst, bound) = tree_residual(&case).unwrap();
    assert!(
        worst > 0.0 && worst <= bound,
        "residual {worst:e} > {bound:e}"
    );
}

/// The worst residual of one tree solve of `case` over its joints' point
/// rows and its bound, `8 n eps (spread) (1 + a2 stiffening) (1 + r²)
/// (speed scale)`.
fn tree_residual(case: &TreeCase) -> Result<(f64, f64), TestCaseError> {
    let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
    let soft = ctx.direct_joint_softness;
    let mut b = build(case, &ctx);
    let m = solve_measured(
        &ctx,
        (&mut b.joints, &mut b.set),
        &case.bodies,
        2,
        case.use_bias,
    )?;
    let mut worst: f64 = 0.0;
    for ((j, rows), k) in b.joints.iter().zip(&m.before).zip(&m.ks) {
        let after = j.rows(&ctx, &b.set);
        let lambda = revolute(j).linear_impulse();
        for i in 0..2 {
            let c_dot = d(after.row_velocity(i, |h| velocity(&b.set, h)));
            let bias = if case.use_bias {
                // The velocity solve's share of the capped feedback
                // (`joint_tree::VELOCITY_CORRECTION_SPEED`; the
                // joints start with no impulse, so nothing is held);
                // the rest moves the bodies in the correction pass.
                let c = Vec2::new(rows.rows[0].c, rows.rows[1].c);
                let clamp = |b: Vec2, cap: Real| {
                    let len = b.length();
                    if len > cap { b * (cap / len) } else { b }
                };
                let full = clamp(soft.bias_rate * c, ctx.direct_joint_max_correction_speed);
                d(clamp(full, VELOCITY_CORRECTION_SPEED)[i])
            } else {
                0.0
            };
            let held = m.compliance * (k[i][0] * d(lambda.x) + k[i][1] * d(lambda.y));
            worst = worst.max((c_dot + bias + held).abs());
        }
    }
    // The rows' K mixes m⁻¹ with r² I⁻¹, so the rounding grows with the
    // longest lever arm too: `|r|²` of a body in a joint is the sum of its
    // angular Jacobian entries squared over the two point rows (`r × x̂`,
    // `r × ŷ`). Without it the bound failed in about one f64 run in
    // thirty (the case of `tree_residual_of_a_second_pin_off_the_centre`).
    let bound = residual_bound(
        &case.bodies,
        b.joints.len(),
        m.stiffening,
        lever_squared(&m.before),
        m.scale,
    );
    Ok((worst, bound))
}

#[test]
fn tree_solve_changes_momentum_only_through_the_pin() {
    let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
    check("tree solve momentum", tree_case(), |case| {
        let mut b = build(&case, &ctx);
        let v0: Vec<(Vec2, Real)> = b.bodies.iter().map(|h| velocity(&b.set, *h)).collect();
        let mut forest = JointForest::default();
        forest.build(&mut b.joints, &b.set.states, true);
        forest.solve(&ctx, &mut b.joints, &mut b.set.states, case.use_bias);
        // The pin is body a of its joints: it takes −λ, the bodies +λ.
        let pin = b
            .joints
            .iter()
            .zip(&b.pinned)
            .filter(|(_, pinned)| **pinned);
        let (err, scale) = pin_momentum_error(
            &b.set,
            &b.bodies,
            &v0,
            |k| d(case.bodies[k].mass),
            pin.map(|(j, _)| revolute(j).linear_impulse()),
        );
        let bound = 64.0 * EPS * scale * (b.joints.len() as f64);
        prop_assert!(err <= bound, "momentum error {err:e} > {bound:e}");
        Ok(err / bound)
    });
}

/// The change of the bodies' total linear momentum since `v0` (their
/// velocities before), less the impulses `pin_impulses` the static pin
/// took (−λ on the pin, +λ on the bodies), and the scale its rounding
/// grows with (a body's momentum relative to its velocity, not its
/// change). `mass_of(k)`: the mass of body `k` of `bodies`.
pub(super) fn pin_momentum_error(
    set: &BodySet,
    bodies: &[BodyHandle],
    v0: &[(Vec2, Real)],
    mass_of: impl Fn(usize) -> f64,
    pin_impulses: impl Iterator<Item = Vec2>,
) -> (f64, f64) {
    let (mut p, mut scale) = ([0.0f64; 2], 1e-12f64);
    for (k, (h, (v, _))) in bodies.iter().zip(v0).enumerate() {
        let m = mass_of(k);
        let dv = velocity(set, *h).0 - *v;
        p[0] += m * d(dv.x);
        p[1] += m * d(dv.y);
        scale = scale.max(m * (d(v.length()) + d(dv.length())));
    }
    for impulse in pin_impulses {
        p[0] -= d(impulse.x);
        p[1] -= d(impulse.y);
    }
    (p[0].hypot(p[1]), scale)
}

/// A joint that closes a loop between moving bodies leaves the whole
/// component to Gauss–Seidel; one more pin to a static body does not.
#[test]
fn joint_loops_stay_gauss_seidel() -> Result<(), TestCaseError> {
    let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
    let spec = |x: Real| BodySpec::dynamic(Vec2::new(x, 0.0), 1.0, 0.1);
    let case = TreeCase {
        bodies: vec![spec(1.0), spec(2.0), spec(3.0)],
        links: vec![
            Link {
                parent: 0,
                anchor_parent: Vec2::ZERO,
                anchor_child: Vec2::new(-0.5, 0.0),
            },
            Link {
                parent: 1,
                anchor_parent: Vec2::new(0.5, 0.0),
                anchor_child: Vec2::new(-0.5, 0.0),
            },
            Link {
                parent: 2,
                anchor_parent: Vec2::new(0.5, 0.0),
                anchor_child: Vec2::new(-0.5, 0.0),
            },
        ],
        extra_pins: vec![(2, Vec2::new(0.5, 0.0))],
        use_bias: true,
    };
    let mut b = build(&case, &ctx);
    let mut forest = JointForest::default();
    forest.build(&mut b.joints, &b.set.states, true);
    assert_eq!(forest.tree_joint_count(), 4, "a second pin keeps a tree");
    // Close a loop: body 3 back to body 1.
    let extra = RevoluteJointDef::new(b.bodies[2], b.bodies[0], Vec2::ZERO, Vec2::ZERO);
    let mut loop_joint = Joint::from(RevoluteJoint::new(extra));
    loop_joint.prepare(&ctx, &b.set);
    b.joints.push(loop_joint);
    forest.build(&mut b.joints, &b.set.states, true);
    assert_eq!(forest.tree_joint_count(), 0);
    assert!(b.joints.iter().all(|j| !j.in_tree()));
    forest.build(&mut b.joints, &b.set.states, false);
    assert_eq!(forest.tree_joint_count(), 0, "switched off");
    Ok(())
}

/// The forest is kept between steps while the joints' ends do not change;
/// a joint destroyed and made again with the same ends (same storage slot)
/// must still join the tree, and one that closes a loop must leave it.
#[test]
fn forest_follows_joints_made_and_destroyed_between_steps() {
    use janus2d::prelude::{BodyDef, World, WorldDef};
    let mut world = World::new(WorldDef::default()).unwrap();
    let pin = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let a = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.5, 0.0)).with_mass(1.0, 0.1))
        .unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(1.5, 0.0)).with_mass(1.0, 0.1))
        .unwrap();
    let half = Vec2::new(0.5, 0.0);
    let j0 = world
        .create_revolute_joint(&RevoluteJointDef::new(pin, a, Vec2::ZERO, -half))
        .unwrap();
    let j1 = world
        .create_revolute_joint(&RevoluteJointDef::new(a, b, half, -half))
        .unwrap();
    world.step(1.0 / 60.0).unwrap();
    let in_tree = |w: &World, j| w.revolute_joint(j).unwrap().in_tree();
    assert!(in_tree(&world, j0) && in_tree(&world, j1));
    world.destroy_joint(j1).unwrap();
    let j1 = world
        .create_revolute_joint(&RevoluteJointDef::new(a, b, half, -half))
        .unwrap();
    world.step(1.0 / 60.0).unwrap();
    assert!(in_tree(&world, j0) && in_tree(&world, j1), "re-made joint");
    let gap = world.max_joint_gap();
    let closing = world
        .create_revolute_joint(&RevoluteJointDef::new(b, a, -half, half))
        .unwrap();
    world.step(1.0 / 60.0).unwrap();
    assert!(!in_tree(&world, j0) && !in_tree(&world, j1) && !in_tree(&world, closing));
    world.destroy_joint(closing).unwrap();
    world.step(1.0 / 60.0).unwrap();
    assert!(in_tree(&world, j0) && in_tree(&world, j1), "loop removed");
    assert!(gap < 1e-3, "gap {gap}");
}
