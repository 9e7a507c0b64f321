//! The box model of one robot: one OBB per lower link, optional extra boxes
//! (thesis 2.5-2.6, SPEC §3).
//!
//! Box `i` of a lower link has centre `(G_i + E_i) / 2`, axes `x = (E_i - G_i) / |E_i - G_i|`,
//! `z = normalize(x cross t_i)`, `y = z cross x`, and half-extents `(re / 2, H, D)`, all three
//! enlarged by the safety `margin` ("blown-up" model). [`RobotModel::boxes`] builds them in
//! this direct vector form (the equivalent of the thesis's simplified equations, 2.6);
//! [`RobotModel::boxes_chain`] builds the same boxes through the thesis's chain of homogeneous
//! transforms M1..M6 (2.5) and exists for comparison and benchmarks (thesis Figure 2.12).
//!
//! # Conventions
//! Box order: lower links 0, 1, 2; then, when switched on, upper links (3 boxes, `F_i` to
//! `G_i`, axes built the same way), the platform, the tool (world-aligned, centred at
//! `tcp + offset`). The margin enlarges every half-extent of every box.
//! In the chain, the thesis leaves the passive elbow angles loose; here `beta_i` and `gamma_i`
//! are derived from `G_i` and `E_i` by [`leg_angles`] so that the chain's pose is exactly the
//! SPEC §3 box (no sign flips).

use crate::geometry::Obb;
use crate::math::{float, Mat3, Real, Vec3, MAX_LENGTH};
use crate::robot::delta3::{radial, tangent, Delta3, MotorCosSin, Unreachable};
use alloc::{format, string::String};
use core::f64::consts::PI;

/// A box hanging from the TCP: centre `tcp + offset`, world-aligned axes, `half` extents.
/// It must enclose the tool over its whole rotation about the fourth axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolBox {
    /// Centre of the box relative to the TCP (mm, MCS axes).
    pub offset: Vec3,
    /// Half-extents along the MCS axes (mm).
    pub half: Vec3,
}

/// What the model contains besides the robot's geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelOptions {
    /// Half-extent `H` of a lower link box across the parallelogram (thesis `H_a`; 70).
    pub half_height: Real,
    /// Half-extent `D` of a lower link box in the arm's plane (thesis `D_a`; 17.5).
    pub half_depth: Real,
    /// Safety margin added to every half-extent of every box (mm, >= 0).
    pub margin: Real,
    /// Upper link boxes: half-extents across `(y = t_i, z)`, or `None` (the thesis's choice).
    pub upper_links: Option<(Real, Real)>,
    /// The moving platform as a box centred at the TCP, or `None`.
    pub platform: Option<ToolBox>,
    /// The tool as a box below the TCP, or `None`.
    pub tool: Option<ToolBox>,
}

impl ModelOptions {
    /// The physical robot of the thesis: H = 70, D = 17.5, no margin, lower links only.
    pub const THESIS: ModelOptions = ModelOptions {
        half_height: 70.0,
        half_depth: 17.5,
        margin: 0.0,
        upper_links: None,
        platform: None,
        tool: None,
    };

    /// Checks that every size is finite and non-negative (box half-extents positive).
    ///
    /// # Errors
    /// A sentence naming the bad option.
    pub fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, v: Real| {
            if v.is_finite() && v > 0.0 && v <= MAX_LENGTH {
                Ok(())
            } else {
                Err(format!("model option {name} = {v} must be a length in (0, {MAX_LENGTH:e}] mm"))
            }
        };
        positive("half_height", self.half_height)?;
        positive("half_depth", self.half_depth)?;
        if !(self.margin.is_finite() && self.margin >= 0.0 && self.margin <= MAX_LENGTH) {
            return Err(format!(
                "safety margin {} must be a length in [0, {MAX_LENGTH:e}] mm",
                self.margin
            ));
        }
        if let Some((h, d)) = self.upper_links {
            positive("upper link half height", h)?;
            positive("upper link half depth", d)?;
        }
        for (name, b) in [("platform", self.platform), ("tool", self.tool)] {
            if let Some(b) = b {
                if !(b.offset.iter().all(|v| v.is_finite() && v.abs() <= MAX_LENGTH)) {
                    return Err(format!(
                        "{name} box offset {:?} must be finite, each |value| <= {MAX_LENGTH:e} mm",
                        b.offset
                    ));
                }
                for v in b.half.iter() {
                    positive(&format!("{name} box half-extent"), *v)?;
                }
            }
        }
        Ok(())
    }
}

/// Which part of the robot a box models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoxKind {
    /// Lower link of arm 0, 1 or 2.
    LowerLink(u8),
    /// Upper link of arm 0, 1 or 2.
    UpperLink(u8),
    /// The moving platform.
    Platform,
    /// The tool.
    Tool,
}

/// Most boxes one robot model may have (3 lower links, 3 upper links, platform, tool): the
/// size of every per-robot box array (the witness cache, the sweeps of the certified
/// labelling), so that a tick never allocates. Defined with the box sets of `geometry`,
/// which hold one robot's boxes.
pub use crate::geometry::MAX_BOXES;

/// Up to [`MAX_BOXES`] boxes of one robot, in a fixed array (no allocation per tick).
#[derive(Clone, Copy, Debug)]
pub struct RobotBoxes {
    /// The boxes; only the first `len` are meaningful.
    pub boxes: [Obb; MAX_BOXES],
    /// How many boxes the model has.
    pub len: usize,
}

impl RobotBoxes {
    /// No boxes.
    pub fn empty() -> Self {
        RobotBoxes {
            boxes: [Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::zeros()); MAX_BOXES],
            len: 0,
        }
    }

    /// The meaningful boxes.
    pub fn as_slice(&self) -> &[Obb] {
        &self.boxes[..self.len]
    }

    fn push(&mut self, b: Obb) {
        self.boxes[self.len] = b;
        self.len += 1;
    }
}

/// A robot's geometry and model options: everything needed to build its boxes from a TCP.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotModel {
    /// Kinematic parameters.
    pub delta: Delta3,
    /// Box sizes, margin and optional boxes.
    pub options: ModelOptions,
}

impl RobotModel {
    /// The thesis robot with the physical box sizes.
    pub const THESIS: RobotModel =
        RobotModel { delta: Delta3::THESIS, options: ModelOptions::THESIS };

    /// How many boxes [`RobotModel::boxes`] returns.
    pub fn box_count(&self) -> usize {
        let o = &self.options;
        3 + if o.upper_links.is_some() { 3 } else { 0 }
            + o.platform.is_some() as usize
            + o.tool.is_some() as usize
    }

    /// What box `index` (< [`RobotModel::box_count`]) models.
    pub fn box_kind(&self, index: usize) -> BoxKind {
        let upper = if self.options.upper_links.is_some() { 3 } else { 0 };
        match index {
            0..=2 => BoxKind::LowerLink(index as u8),
            i if i < 3 + upper => BoxKind::UpperLink((i - 3) as u8),
            i if i == 3 + upper && self.options.platform.is_some() => BoxKind::Platform,
            _ => BoxKind::Tool,
        }
    }

    /// The boxes of the robot with its TCP at `tcp` (MCS), in the MCS; direct form.
    ///
    /// # Errors
    /// [`Unreachable`] from the inverse kinematics.
    #[inline]
    pub fn boxes(&self, tcp: &Vec3) -> Result<RobotBoxes, Unreachable> {
        let sol = self.delta.inverse_kinematics_cos_sin(tcp)?;
        Ok(self.boxes_from_cos_sin(tcp, &sol))
    }

    /// [`RobotModel::boxes`] written into a caller-owned buffer (no copy of the ~1 KB
    /// [`RobotBoxes`]; the per-tick path). Boxes past `out.len` are left as they were.
    ///
    /// # Errors
    /// [`Unreachable`] from the inverse kinematics; `out` is then left unchanged.
    pub fn boxes_into(&self, tcp: &Vec3, out: &mut RobotBoxes) -> Result<(), Unreachable> {
        let sol = self.delta.inverse_kinematics_cos_sin(tcp)?;
        self.write_boxes(tcp, &sol, out);
        Ok(())
    }

    /// The boxes for a TCP and the cosines and sines of its motor angles (direct vector form,
    /// SPEC §3: centre `(G + E) / 2`, `x = (E - G) / |E - G|`, `z = normalize(x cross t)`).
    pub fn boxes_from_cos_sin(&self, tcp: &Vec3, sol: &MotorCosSin) -> RobotBoxes {
        let mut out = RobotBoxes::empty();
        self.write_boxes(tcp, sol, &mut out);
        out
    }

    /// Box `k` alone of [`RobotModel::boxes_from_cos_sin`] (the same operations, so the same
    /// box), in the MCS: one box of a configuration without building the others.
    pub fn box_from_cos_sin(&self, tcp: &Vec3, sol: &MotorCosSin, k: usize) -> Obb {
        let (d, o) = (&self.delta, &self.options);
        let m = o.margin;
        let elbow = |arm: usize| d.elbow(arm, sol.cos[arm], sol.sin[arm]);
        match self.box_kind(k) {
            BoxKind::LowerLink(arm) => {
                let (arm, lower_half) =
                    (arm as usize, Vec3::new(0.5 * d.re + m, o.half_height + m, o.half_depth + m));
                link_box(
                    &elbow(arm),
                    &d.platform_joint(arm, tcp),
                    1.0 / d.re,
                    &tangent(arm),
                    lower_half,
                )
            }
            BoxKind::UpperLink(arm) => {
                let (h, dz) = o.upper_links.expect("upper link boxes exist");
                let (arm, upper_half) = (arm as usize, Vec3::new(0.5 * d.rf + m, h + m, dz + m));
                link_box(&d.motor_point(arm), &elbow(arm), 1.0 / d.rf, &tangent(arm), upper_half)
            }
            BoxKind::Platform | BoxKind::Tool => {
                let extra = if self.box_kind(k) == BoxKind::Platform { o.platform } else { o.tool };
                let extra = extra.expect("the box exists");
                Obb::new(tcp + extra.offset, Mat3::identity(), extra.half.add_scalar(m))
            }
        }
    }

    fn write_boxes(&self, tcp: &Vec3, sol: &MotorCosSin, out: &mut RobotBoxes) {
        let (d, o) = (&self.delta, &self.options);
        let m = o.margin;
        // |E_i - G_i| = re once the loops close (IK: to ~1e-15 relative), so x = (E - G) / re.
        let (inv_re, inv_rf) = (1.0 / d.re, 1.0 / d.rf);
        let lower_half = Vec3::new(0.5 * d.re + m, o.half_height + m, o.half_depth + m);
        let elbows: [Vec3; 3] =
            core::array::from_fn(|arm| d.elbow(arm, sol.cos[arm], sol.sin[arm]));
        for (arm, slot) in out.boxes[..3].iter_mut().enumerate() {
            *slot = link_box(
                &elbows[arm],
                &d.platform_joint(arm, tcp),
                inv_re,
                &tangent(arm),
                lower_half,
            );
        }
        out.len = 3;
        if let Some((h, dz)) = o.upper_links {
            let upper_half = Vec3::new(0.5 * d.rf + m, h + m, dz + m);
            for (arm, g) in elbows.iter().enumerate() {
                out.push(link_box(&d.motor_point(arm), g, inv_rf, &tangent(arm), upper_half));
            }
        }
        // Each optional box read in place: an array of both options would copy them every call.
        for extra in [&o.platform, &o.tool].into_iter().flatten() {
            out.push(Obb::new(tcp + extra.offset, Mat3::identity(), extra.half.add_scalar(m)));
        }
    }

    /// The same boxes as [`RobotModel::boxes`], computed through the chain of homogeneous
    /// transforms of thesis 2.5, `M1 M2 M3 M4 M5 M6` per lower link (slower; kept to
    /// compare and benchmark, thesis Figure 2.12). `M1`, WCS to MCS, is the identity here
    /// because the boxes are wanted in the robot's own MCS.
    ///
    /// # Errors
    /// [`Unreachable`] from the inverse kinematics.
    pub fn boxes_chain(&self, tcp: &Vec3) -> Result<RobotBoxes, Unreachable> {
        let (d, o) = (&self.delta, &self.options);
        let sol = d.inverse_kinematics(tcp)?;
        let m = o.margin;
        let m1 = homogeneous(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        // Body frames of the upper links after the motor rotation: x along F_i G_i, y = t_i.
        let motor_frames: [Mat4; 3] = core::array::from_fn(|arm| {
            let f = d.motor_point(arm);
            let m2 = homogeneous(f.x, f.y, f.z, 0.0, 0.0, arm as Real * 2.0 * PI / 3.0);
            let m3 = homogeneous(0.0, 0.0, 0.0, 0.0, sol.theta[arm], 0.0);
            m1 * m2 * m3
        });
        let mut out = RobotBoxes::empty();
        let lower_half = Vec3::new(0.5 * d.re + m, o.half_height + m, o.half_depth + m);
        for (arm, m123) in motor_frames.iter().enumerate() {
            let g = d.elbow(arm, sol.cos[arm], sol.sin[arm]);
            let e = d.platform_joint(arm, tcp);
            let (beta, gamma) = leg_angles(arm, &g, &e);
            let m4 = homogeneous(d.rf, 0.0, 0.0, 0.0, PI - beta - sol.theta[arm], 0.0);
            let m5 = homogeneous(0.0, 0.0, 0.0, 0.0, 0.0, gamma);
            let m6 = homogeneous(0.5 * (e - g).norm(), 0.0, 0.0, 0.0, 0.0, 0.0);
            out.push(pose_box(&(m123 * m4 * m5 * m6), lower_half));
        }
        if let Some((h, dz)) = o.upper_links {
            let upper_half = Vec3::new(0.5 * d.rf + m, h + m, dz + m);
            for m123 in &motor_frames {
                out.push(pose_box(
                    &(m123 * homogeneous(0.5 * d.rf, 0.0, 0.0, 0.0, 0.0, 0.0)),
                    upper_half,
                ));
            }
        }
        for extra in [o.platform, o.tool].into_iter().flatten() {
            let c = tcp + extra.offset;
            out.push(pose_box(
                &(m1 * homogeneous(c.x, c.y, c.z, 0.0, 0.0, 0.0)),
                extra.half.add_scalar(m),
            ));
        }
        Ok(out)
    }
}

/// A 4x4 homogeneous transform.
pub type Mat4 = nalgebra::Matrix4<Real>;

/// The thesis's `M(x, y, z, alpha, beta, gamma)` (2.4.2): rotate by `alpha` about x, then
/// `beta` about y, then `gamma` about z (`Rz Ry Rx`), then translate by `(x, y, z)`.
pub fn homogeneous(x: Real, y: Real, z: Real, alpha: Real, beta: Real, gamma: Real) -> Mat4 {
    let (sa, ca) = float::sin_cos(alpha);
    let (sb, cb) = float::sin_cos(beta);
    let (sg, cg) = float::sin_cos(gamma);
    #[rustfmt::skip]
    let m = Mat4::new(
        cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa, x,
        sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa, y,
        -sb,     cb * sa,                cb * ca,                z,
        0.0,     0.0,                    0.0,                    1.0,
    );
    m
}

/// The passive angles of the elbow of `arm` (thesis 2.5, Figure 2.11): `beta` about the
/// body y axis and `gamma` about the body z axis, chosen so that `Ry(pi - beta)` then
/// `Rz(gamma)` in the arm frame `(u_i, t_i, z)` turn x onto `(E - G) / |E - G|`. Then the
/// chain's y and z axes are exactly the SPEC §3 ones (`gamma` in [-pi/2, pi/2]).
pub fn leg_angles(arm: usize, g: &Vec3, e: &Vec3) -> (Real, Real) {
    let x = (e - g).normalize();
    let (xu, xt, xz) = (x.dot(&radial(arm)), x.dot(&tangent(arm)), x.z);
    // Ry(pi - beta) x = (-cos beta, 0, -sin beta); Rz(gamma) mixes in t with sin gamma.
    let gamma = float::atan2(xt, float::hypot(xu, xz));
    let beta = float::atan2(-xz, -xu);
    (beta, gamma)
}

/// The box whose centre and axes are the origin and the rotation of the pose `m`.
fn pose_box(m: &Mat4, half: Vec3) -> Obb {
    let center = Vec3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
    Obb::new(center, m.fixed_view::<3, 3>(0, 0).into_owned(), half)
}

/// Below this `|x cross t|` the link runs (nearly) along its motor axis and `x cross t` no
/// longer fixes the box's roll about x: it is taken from the vertical instead.
///
/// At 1e-6 the cross product still has about ten exact digits (its rounding is ~1e-16), so
/// the axes stay orthonormal to ~1e-10 and a box of 200 mm half-extent keeps its extent to
/// ~1e-8 mm, below the SAT's touch tolerance.
const PARALLEL_TO_MOTOR_AXIS: Real = 1e-6;

/// The box around the segment `p -> q` of length `1 / inv_len`: x along it,
/// z = normalize(x cross t), y = z cross x (SPEC §3).
///
/// When the link is parallel to `t` (a TCP at `|b| = re`, on the reach boundary: lower link
/// along the motor axis), `x cross t` vanishes and SPEC §3's frame is undefined. Any roll of
/// the box about x then models the link equally well; z is taken as the unit vector across
/// x in the plane of x and the vertical, so that the axes stay an orthonormal frame and the
/// box keeps its extent (a NaN frame would make the box vanish from every test).
fn link_box(p: &Vec3, q: &Vec3, inv_len: Real, t: &Vec3, half: Vec3) -> Obb {
    let x = (q - p) * inv_len;
    let xt = x.cross(t);
    let n = xt.norm();
    let z = if n > PARALLEL_TO_MOTOR_AXIS {
        xt * (1.0 / n)
    } else {
        // x is within 1e-6 rad of t, which is horizontal, so x cross z_world has norm ~1.
        let xv = x.cross(&Vec3::z());
        xv * (1.0 / xv.norm())
    };
    let y = z.cross(&x);
    Obb::new((p + q) * 0.5, Mat3::from_columns(&[x, y, z]), half)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One box alone is the same box, to the bit, as among all of them, for every box kind.
    #[test]
    fn one_box_is_that_box_of_all() {
        let mut rng = crate::test_rng::TestRng(7);
        for model in [RobotModel::THESIS, full_options(5.0)] {
            let mut tried = 0;
            while tried < 500 {
                let tcp =
                    Vec3::new(400.0 * rng.unit(), 400.0 * rng.unit(), -650.0 + 350.0 * rng.unit());
                let Ok(sol) = model.delta.inverse_kinematics_cos_sin(&tcp) else {
                    assert!(model.boxes(&tcp).is_err());
                    continue;
                };
                let all = model.boxes(&tcp).unwrap();
                for (k, b) in all.as_slice().iter().enumerate() {
                    assert_eq!(model.box_from_cos_sin(&tcp, &sol, k), *b, "box {k} at {tcp:?}");
                }
                tried += 1;
            }
        }
    }

    #[test]
    fn lower_link_box_spans_elbow_to_platform_joint() {
        let model = RobotModel::THESIS;
        let tcp = Vec3::new(50.0, -30.0, -450.0);
        let sol = model.delta.inverse_kinematics(&tcp).unwrap();
        let boxes = model.boxes(&tcp).unwrap();
        assert_eq!(boxes.len, 3);
        for arm in 0..3 {
            let b = &boxes.boxes[arm];
            let g = model.delta.elbow(arm, sol.cos[arm], sol.sin[arm]);
            let e = model.delta.platform_joint(arm, &tcp);
            assert!((b.center - b.axes.column(0) * b.half.x - g).norm() < 1e-9);
            assert!((b.center + b.axes.column(0) * b.half.x - e).norm() < 1e-9);
            assert!((b.axes.transpose() * b.axes - Mat3::identity()).norm() < 1e-12);
            assert!(b.axes.column(1).dot(&tangent(arm)) > 0.9, "y stays close to t_i");
        }
    }

    /// At `y = re`, `(60, 400, -150)` puts lower link 0 exactly along its motor axis: its
    /// frame falls back to the vertical and stays orthonormal, and near it the usual frame
    /// is used without a jump in extent.
    #[test]
    fn link_along_its_motor_axis_keeps_an_orthonormal_frame() {
        let model = RobotModel::THESIS;
        for tcp in [Vec3::new(60.0, 400.0, -150.0), Vec3::new(60.0, 400.0 - 1e-7, -150.0)] {
            let Ok(sol) = model.delta.inverse_kinematics(&tcp) else { continue };
            let boxes = model.boxes(&tcp).unwrap();
            let b = &boxes.boxes[0];
            assert!(
                (b.axes.transpose() * b.axes - Mat3::identity()).norm() < 1e-9,
                "{tcp:?}: {b:?}"
            );
            let g = model.delta.elbow(0, sol.cos[0], sol.sin[0]);
            assert!((b.center - b.axes.column(0) * b.half.x - g).norm() < 1e-9);
            assert!(
                b.axes.column(0).cross(&tangent(0)).norm() < 1e-3,
                "{tcp:?}: link 0 runs along t_0"
            );
        }
        assert!(
            model.delta.inverse_kinematics(&Vec3::new(60.0, 400.0, -150.0)).is_ok(),
            "the exact pose is reachable"
        );
    }

    fn full_options(margin: Real) -> RobotModel {
        RobotModel {
            delta: Delta3::THESIS,
            options: ModelOptions {
                margin,
                upper_links: Some((30.0, 20.0)),
                platform: Some(ToolBox {
                    offset: Vec3::new(0.0, 0.0, 10.0),
                    half: Vec3::new(60.0, 60.0, 15.0),
                }),
                tool: Some(ToolBox {
                    offset: Vec3::new(0.0, 0.0, -40.0),
                    half: Vec3::new(25.0, 25.0, 40.0),
                }),
                ..ModelOptions::THESIS
            },
        }
    }

    #[test]
    fn box_kinds_follow_box_order_for_every_option_set() {
        let base = full_options(0.0);
        let tcp = Vec3::new(20.0, 40.0, -430.0);
        for mask in 0..8u8 {
            let mut model = base;
            model.options.upper_links = if mask & 1 != 0 { base.options.upper_links } else { None };
            model.options.platform = if mask & 2 != 0 { base.options.platform } else { None };
            model.options.tool = if mask & 4 != 0 { base.options.tool } else { None };
            let n = model.box_count();
            assert_eq!(
                n,
                3 + 3 * (mask & 1) as usize + (mask >> 1 & 1) as usize + (mask >> 2 & 1) as usize
            );
            assert_eq!(model.boxes(&tcp).unwrap().len, n);
            assert_eq!(model.boxes_chain(&tcp).unwrap().len, n);
            let kinds: Vec<BoxKind> = (0..n).map(|i| model.box_kind(i)).collect();
            let mut expected: Vec<BoxKind> = (0..3).map(BoxKind::LowerLink).collect();
            if mask & 1 != 0 {
                expected.extend((0..3).map(BoxKind::UpperLink));
            }
            if mask & 2 != 0 {
                expected.push(BoxKind::Platform);
            }
            if mask & 4 != 0 {
                expected.push(BoxKind::Tool);
            }
            assert_eq!(kinds, expected, "mask {mask}");
        }
    }

    #[test]
    fn options_are_validated() {
        assert!(ModelOptions::THESIS.validate().is_ok());
        assert!(full_options(3.0).options.validate().is_ok());
        assert!(ModelOptions { margin: -1.0, ..ModelOptions::THESIS }
            .validate()
            .unwrap_err()
            .contains("margin"));
        assert!(ModelOptions { half_depth: f64::NAN, ..ModelOptions::THESIS }.validate().is_err());
        let mut o = full_options(0.0).options;
        o.tool = Some(ToolBox { offset: Vec3::zeros(), half: Vec3::new(1.0, 0.0, 1.0) });
        assert!(o.validate().unwrap_err().contains("tool"));
    }

    #[test]
    fn margin_grows_every_half_extent_by_exactly_m() {
        let tcp = Vec3::new(-70.0, 15.0, -480.0);
        let plain = full_options(0.0).boxes(&tcp).unwrap();
        let blown = full_options(12.5).boxes(&tcp).unwrap();
        for (a, b) in plain.as_slice().iter().zip(blown.as_slice()) {
            assert_eq!(b.half, a.half.add_scalar(12.5));
            assert_eq!(a.center, b.center);
            assert_eq!(a.axes, b.axes);
        }
    }

    #[test]
    fn upper_link_box_spans_motor_point_to_elbow() {
        let model = full_options(0.0);
        let tcp = Vec3::new(100.0, -60.0, -400.0);
        let sol = model.delta.inverse_kinematics(&tcp).unwrap();
        let boxes = model.boxes(&tcp).unwrap();
        for arm in 0..3 {
            let b = &boxes.boxes[3 + arm];
            let f = model.delta.motor_point(arm);
            let g = model.delta.elbow(arm, sol.cos[arm], sol.sin[arm]);
            assert!((b.center - b.axes.column(0) * b.half.x - f).norm() < 1e-9);
            assert!((b.center + b.axes.column(0) * b.half.x - g).norm() < 1e-9);
            assert!((b.axes.column(1) - tangent(arm)).norm() < 1e-12, "upper link y is t_i");
        }
        assert_eq!(boxes.boxes[6].center, tcp + Vec3::new(0.0, 0.0, 10.0));
        assert_eq!(boxes.boxes[7].center, tcp + Vec3::new(0.0, 0.0, -40.0));
    }

    #[test]
    fn chain_and_direct_forms_agree() {
        for margin in [0.0, 7.0] {
            let model = full_options(margin);
            for tcp in [
                Vec3::new(0.0, 0.0, -450.0),
                Vec3::new(150.0, -90.0, -410.0),
                Vec3::new(-120.0, 120.0, -470.0),
            ] {
                let (a, b) = (model.boxes(&tcp).unwrap(), model.boxes_chain(&tcp).unwrap());
                for (x, y) in a.as_slice().iter().zip(b.as_slice()) {
                    assert!((x.center - y.center).norm() < 1e-9, "{x:?} vs {y:?}");
                    assert!((x.axes - y.axes).norm() < 1e-9, "{x:?} vs {y:?}");
                    assert!((x.half - y.half).norm() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn homogeneous_transform_matches_nalgebra_euler_angles() {
        let m = homogeneous(1.0, -2.0, 3.0, 0.3, -0.7, 1.9);
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.9);
        assert!((m.fixed_view::<3, 3>(0, 0) - r.matrix()).norm() < 1e-15);
        assert_eq!((m[(0, 3)], m[(1, 3)], m[(2, 3)], m[(3, 3)]), (1.0, -2.0, 3.0, 1.0));
    }
}
