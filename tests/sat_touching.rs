//! Exactly touching boxes collide (SPEC §3: boxes are closed), and libccd-style sweeps walk
//! one box through another asserting every step, touching steps included (thesis 3.1).
//! Checked without parry, which misses many exactly touching pairs.

use delta_collide::geometry::{separating_axis, Obb};
use delta_collide::math::{Mat3, Real, Vec3};

fn boxed(c: [Real; 3], m: Mat3, h: [Real; 3]) -> Obb {
    Obb::new(Vec3::from(c), m, Vec3::from(h))
}

fn assert_collide(a: &Obb, b: &Obb, what: &str) {
    assert!(
        separating_axis(a, b).is_none(),
        "{what}: touching boxes must collide\n    a = {a:?}\n    b = {b:?}"
    );
    assert!(separating_axis(b, a).is_none(), "{what} (swapped): touching boxes must collide");
}

fn assert_free(a: &Obb, b: &Obb, what: &str) {
    assert!(
        separating_axis(a, b).is_some(),
        "{what}: separated boxes must be free\n    a = {a:?}\n    b = {b:?}"
    );
}

/// All 48 signed permutation matrices: exact rotations (and reflections, harmless here).
fn signed_permutations() -> Vec<Mat3> {
    let perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
    let mut out = Vec::new();
    for p in perms {
        for s in 0..8 {
            let mut m = Mat3::zeros();
            for (col, &row) in p.iter().enumerate() {
                m[(row, col)] = if s >> col & 1 == 0 { 1.0 } else { -1.0 };
            }
            out.push(m);
        }
    }
    out
}

/// Face on face, edge on face, vertex on vertex with axis-aligned boxes and dyadic
/// coordinates, under every signed permutation of the scene: exact arithmetic throughout.
#[test]
fn exactly_touching_axis_aligned_boxes_collide() {
    let ha = [200.0, 70.0, 17.5];
    let hb = [40.0, 12.5, 3.25];
    // B's centre offsets, each touching A: along x (face), x+y (edge), x+y+z (vertex), with
    // partial lateral overlap.
    let offsets = [
        [240.0, 30.0, -5.0],
        [240.0, 82.5, 0.0],
        [240.0, 82.5, 20.75],
        [-240.0, -82.5, -20.75],
        [100.0, -82.5, 20.75],
        [0.0, 0.0, 20.75],
    ];
    for m in signed_permutations() {
        for off in offsets {
            let a = boxed([1.5, -2.25, 1000.0], m, ha);
            let rel = m * Vec3::from(off);
            let b = boxed([1.5 + rel.x, -2.25 + rel.y, 1000.0 + rel.z], m, hb);
            assert_collide(&a, &b, "axis-aligned touching");
            // 1/64 mm further out along the offset separates.
            let out = m * Vec3::from(off).map(|v| v + v.signum() / 64.0);
            let b_out = boxed([1.5 + out.x, -2.25 + out.y, 1000.0 + out.z], m, hb);
            assert_free(&a, &b_out, "1/64 mm apart");
        }
    }
}

/// B turned about the contact normal keeps its extent along it exactly, so face-face
/// contact stays exact with a general rotation of B in the contact plane.
#[test]
fn exactly_touching_faces_with_rotated_box_collide() {
    let ha = [200.0, 70.0, 17.5];
    let hb = [30.0, 20.0, 5.0];
    for k in 0..3 {
        for step in 0..64 {
            let angle = step as Real * 0.1;
            let mut m = Mat3::identity();
            let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
            m[(k1, k1)] = angle.cos();
            m[(k2, k1)] = angle.sin();
            m[(k1, k2)] = -angle.sin();
            m[(k2, k2)] = angle.cos();
            let mut c = [0.0; 3];
            c[k] = ha[k] + hb[k];
            assert_collide(
                &boxed([0.0; 3], Mat3::identity(), ha),
                &boxed(c, m, hb),
                "face-face rotated",
            );
            c[k] += 1.0 / 1024.0;
            assert_free(
                &boxed([0.0; 3], Mat3::identity(), ha),
                &boxed(c, m, hb),
                "face-face rotated, apart",
            );
        }
    }
}

/// A rotation whose columns come from a general rotation: contact positions then carry
/// rounding (about 1e-13 mm), which the touch tolerance must absorb on the collision side.
fn rotation(roll: Real, pitch: Real, yaw: Real) -> Mat3 {
    *nalgebra::Rotation3::from_euler_angles(roll, pitch, yaw).matrix()
}

/// Crossed edges: A turned 45 degrees about x shows a ridge along x on top, B turned 45
/// degrees about y shows a ridge along y underneath; B sits exactly on A's ridge. The whole
/// scene is then moved by a general rigid motion.
#[test]
fn crossed_edges_touching_collide() {
    let q = std::f64::consts::FRAC_PI_4;
    for (s, &(ha, hb)) in
        [([200.0, 70.0, 70.0], [17.5, 200.0, 17.5]), ([50.0, 3.0, 8.0], [2.0, 90.0, 11.0])]
            .iter()
            .enumerate()
    {
        let ma = rotation(q, 0.0, 0.0);
        let mb = rotation(0.0, q, 0.0);
        let top_a = (ha[1] + ha[2]) * q.sin();
        let bottom_b = (hb[0] + hb[2]) * q.sin();
        for step in 0..50 {
            let scene =
                rotation(step as Real * 0.37, step as Real * 0.11 - 1.0, step as Real * 0.23);
            let shift = Vec3::new(step as Real * 13.0, -500.0, 250.0);
            let a = Obb::new(shift, scene * ma, Vec3::from(ha));
            let b = Obb::new(
                scene * Vec3::new(3.0, -5.0, top_a + bottom_b) + shift,
                scene * mb,
                Vec3::from(hb),
            );
            assert_collide(&a, &b, &format!("crossed edges, set {s}, step {step}"));
            let b_up = Obb::new(
                scene * Vec3::new(3.0, -5.0, top_a + bottom_b + 1e-3) + shift,
                scene * mb,
                Vec3::from(hb),
            );
            assert_free(&a, &b_up, "crossed edges 1e-3 mm apart");
        }
    }
}

/// B stands on one vertex on A's top face (B's diagonal along z), under general rigid
/// motions of the scene and general spins of B about the vertical.
#[test]
fn vertex_on_face_touching_collides() {
    let ha = [200.0, 70.0, 17.5];
    let hb = Vec3::new(20.0, 7.0, 3.0);
    for step in 0..200 {
        let spin = rotation(0.0, 0.0, step as Real * 0.031);
        // Turn B's diagonal (1, 1, 1)-corner direction onto -z.
        let diag = hb.normalize();
        let tilt = *nalgebra::Rotation3::rotation_between(&diag, &-Vec3::z()).unwrap().matrix();
        let mb = spin * tilt;
        let lowest = (0..3).map(|k| mb.column(k).z.abs() * hb[k]).sum::<Real>();
        let scene = rotation(step as Real * 0.05, -0.7, step as Real * 0.013);
        let shift = Vec3::new(-300.0, 400.0 + step as Real, 10.0);
        let a = Obb::new(shift, scene, Vec3::from(ha));
        let place = |dz: Real| {
            Obb::new(scene * Vec3::new(-50.0, 20.0, ha[2] + lowest + dz) + shift, scene * mb, hb)
        };
        assert_collide(&a, &place(0.0), &format!("vertex on face, step {step}"));
        assert_collide(&a, &place(-1e-3), "vertex 1e-3 mm into the face");
        assert_free(&a, &place(1e-3), "vertex 1e-3 mm above the face");
    }
}

// ---------------------------------------------------------------- sweeps (libccd style)

/// Walks B through A along axis `k` in steps of 1/64 mm near contact (1/4 mm elsewhere),
/// asserting every step: collision exactly when `|offset| <= touch`, touching included.
fn sweep(a: &Obb, hb: Vec3, mb: Mat3, k: usize, touch: Real, lateral: Vec3) {
    let mut offsets: Vec<Real> = (-2000..=2000).map(|i| i as Real / 4.0).collect();
    offsets
        .extend((-256..=256).flat_map(|i| [touch + i as Real / 64.0, -touch + i as Real / 64.0]));
    offsets.extend([touch, -touch]);
    for off in offsets {
        let mut c = lateral;
        c[k] += off;
        let b = Obb::new(a.center + a.axes * c, a.axes * mb, hb);
        let collide = separating_axis(a, &b).is_none();
        if off.abs() <= touch {
            assert!(collide, "sweep along {k}: offset {off} <= touch {touch} must collide\n  a = {a:?}\n  b = {b:?}");
        } else if off.abs() >= touch + 1e-3 {
            assert!(!collide, "sweep along {k}: offset {off} > touch {touch} must be free\n  a = {a:?}\n  b = {b:?}");
        }
    }
}

#[test]
fn sweeps_through_a_box_along_each_axis() {
    let ha = Vec3::new(200.0, 70.0, 17.5);
    let hb = Vec3::new(10.0, 5.0, 2.0);
    for (frame, center) in [
        (Mat3::identity(), Vec3::zeros()),
        (rotation(0.4, -1.2, 2.5), Vec3::new(812.0, -97.5, -430.25)),
    ] {
        let a = Obb::new(center, frame, ha);
        for k in 0..3 {
            // B axis-aligned with A: exact touching offsets.
            sweep(&a, hb, Mat3::identity(), k, ha[k] + hb[k], Vec3::zeros());
            // B in a general orientation, small enough that its extreme vertex meets A's face.
            let mb = rotation(0.3 + k as Real, 0.9, -0.2);
            let reach = (0..3).map(|j| mb[(k, j)].abs() * hb[j]).sum::<Real>();
            sweep(&a, hb, mb, k, ha[k] + reach, Vec3::zeros());
            // The same, off the centre line by a few mm (still over the face).
            let mut lateral = Vec3::new(3.0, -2.5, 1.25);
            lateral[k] = 0.0;
            sweep(&a, hb, mb, k, ha[k] + reach, lateral);
        }
    }
}
