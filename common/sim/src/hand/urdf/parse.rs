//! Reading a URDF robot and its settings into a [`HandDescription`], one step per URDF element
//! or settings section: links, the joint tree, degrees of freedom, their roles (the settings'
//! `[joints]`), fingers (`fingers`) and collision bodies. Each step checks what it reads, in
//! this order, so that a file with several faults is reported by its first.

use nalgebra::{Unit, Vector3};

use super::{
    Body, CloseTowards, Dof, HandDescription, HandSettings, JointModel, LinkShape, Motion,
    RawShape, Role, bad, clamp_to, pose_of, urdf_error,
};
use crate::error::{Result, ensure_finite};

/// A collision body with its name, its finger and its shape.
type NamedBody = (Body, String, Option<usize>, RawShape);

/// The joints as a tree over the links.
struct Tree {
    /// The joint whose child each link is (`None` for the root).
    parent_joint: Vec<Option<usize>>,
    /// Each joint's (parent, child) links.
    ends: Vec<(usize, usize)>,
    /// The root (palm) link.
    root: usize,
    /// Joints in an order where parents come before children.
    order: Vec<usize>,
}

/// The joints' motions and degrees of freedom, in file order.
struct Dofs {
    motions: Vec<Motion>,
    /// Each joint's degree of freedom (`None` for fixed joints).
    dof_of_joint: Vec<Option<usize>>,
    dofs: Vec<Dof>,
}

impl HandDescription {
    /// Parses URDF text and optional settings; `file` names the URDF in errors.
    pub fn parse(file: &str, urdf: &str, settings: Option<&HandSettings>) -> Result<Self> {
        let robot = urdf_rs::read_from_string(urdf).map_err(|e| bad(file, urdf_error(&e)))?;
        let default_settings = HandSettings::default();
        let settings = settings.unwrap_or(&default_settings);
        let rz = settings.rz(file)?;
        let link_names = link_names(file, &robot)?;
        let tree = tree(file, &robot, &link_names)?;
        let mut d = degrees_of_freedom(file, &robot)?;
        assign_roles(file, &robot, settings, &mut d)?;
        let joints: Vec<JointModel> = tree
            .order
            .iter()
            .map(|&j| JointModel {
                parent: tree.ends[j].0,
                child: tree.ends[j].1,
                origin: pose_of(&robot.joints[j].origin),
                motion: d.motions[j],
                dof: d.dof_of_joint[j],
            })
            .collect();
        let (finger_of_link, finger_count) =
            fingers(file, settings, &link_names, &tree, &d.motions)?;
        let bodies = collision_bodies(file, &robot, tree.root, &finger_of_link)?;
        if bodies.is_empty() {
            return Err(bad(file, "no link has collision geometry"));
        }
        for jm in &joints {
            ensure_finite(jm.origin.to_homogeneous().as_slice(), "a joint origin")?;
        }
        Ok(Self {
            file: file.to_string(),
            name: settings.name.clone().unwrap_or_else(|| robot.name.clone()),
            link_names,
            joints,
            dofs: d.dofs,
            bodies,
            finger_count,
            rz,
        })
    }

    /// Mesh files the description refers to, as written in the URDF.
    pub fn mesh_files(&self) -> Vec<String> {
        self.bodies
            .iter()
            .filter_map(|b| match &b.3 {
                RawShape::Mesh { filename, .. } => Some(filename.clone()),
                RawShape::Ready(_) => None,
            })
            .collect()
    }
}

/// `<link>`s: their names, at least one, each defined once.
fn link_names(file: &str, robot: &urdf_rs::Robot) -> Result<Vec<String>> {
    let link_names: Vec<String> = robot.links.iter().map(|l| l.name.clone()).collect();
    if link_names.is_empty() {
        return Err(bad(file, "no links"));
    }
    for (i, l) in link_names.iter().enumerate() {
        if link_names[..i].contains(l) {
            return Err(bad(file, format!("link `{l}` is defined twice")));
        }
    }
    Ok(link_names)
}

/// `<joint>`s' parents and children: every link is the child of at most one joint; one root;
/// no loop.
fn tree(file: &str, robot: &urdf_rs::Robot, link_names: &[String]) -> Result<Tree> {
    let (parent_joint, ends) = joint_ends(file, robot, link_names)?;
    let root = root_link(file, link_names, &parent_joint)?;
    let order = joint_order(file, link_names, &ends, root)?;
    Ok(Tree {
        parent_joint,
        ends,
        root,
        order,
    })
}

/// Each link's parent joint and each joint's (parent, child) links.
#[allow(clippy::type_complexity)]
fn joint_ends(
    file: &str,
    robot: &urdf_rs::Robot,
    link_names: &[String],
) -> Result<(Vec<Option<usize>>, Vec<(usize, usize)>)> {
    let link_index = |name: &str, joint: &str| -> Result<usize> {
        link_names.iter().position(|l| l == name).ok_or_else(|| {
            bad(
                file,
                format!("joint `{joint}` names the link `{name}`, which is not defined"),
            )
        })
    };
    let mut parent_joint: Vec<Option<usize>> = vec![None; link_names.len()];
    let mut ends = Vec::with_capacity(robot.joints.len());
    for (j, joint) in robot.joints.iter().enumerate() {
        if robot.joints[..j].iter().any(|o| o.name == joint.name) {
            return Err(bad(
                file,
                format!("joint `{}` is defined twice", joint.name),
            ));
        }
        let p = link_index(&joint.parent.link, &joint.name)?;
        let c = link_index(&joint.child.link, &joint.name)?;
        if let Some(other) = parent_joint[c] {
            return Err(bad(
                file,
                format!(
                    "kinematic loop: link `{}` is the child of joints `{}` and `{}` (a hand must be a tree)",
                    link_names[c], robot.joints[other].name, joint.name
                ),
            ));
        }
        parent_joint[c] = Some(j);
        ends.push((p, c));
    }
    Ok((parent_joint, ends))
}

/// The one link that is no joint's child: the palm.
fn root_link(file: &str, link_names: &[String], parent_joint: &[Option<usize>]) -> Result<usize> {
    let roots: Vec<usize> = (0..link_names.len())
        .filter(|&l| parent_joint[l].is_none())
        .collect();
    match roots.as_slice() {
        [r] => Ok(*r),
        [] => Err(bad(
            file,
            "kinematic loop: every link is the child of a joint, so there is no root (palm) link",
        )),
        many => {
            let names: Vec<&str> = many.iter().map(|&l| link_names[l].as_str()).collect();
            Err(bad(
                file,
                format!(
                    "several root links ({}): a hand has one palm link that every other link hangs from",
                    names.join(", ")
                ),
            ))
        }
    }
}

/// Joint order: file order, except that a joint comes after the joint that places its parent
/// link.
fn joint_order(
    file: &str,
    link_names: &[String],
    ends: &[(usize, usize)],
    root: usize,
) -> Result<Vec<usize>> {
    let mut order: Vec<usize> = Vec::new();
    let mut seen = vec![false; link_names.len()];
    seen[root] = true;
    let mut placed = vec![false; ends.len()];
    while let Some(j) = (0..ends.len()).find(|&j| !placed[j] && seen[ends[j].0]) {
        let c = ends[j].1;
        if seen[c] {
            return Err(bad(
                file,
                format!("kinematic loop through link `{}`", link_names[c]),
            ));
        }
        seen[c] = true;
        placed[j] = true;
        order.push(j);
    }
    if let Some(l) = seen.iter().position(|s| !s) {
        return Err(bad(
            file,
            format!(
                "kinematic loop: link `{}` cannot be reached from the root link `{}`",
                link_names[l], link_names[root]
            ),
        ));
    }
    Ok(order)
}

/// Each `<joint>`'s motion, and a degree of freedom (held at its lower limit until
/// [`assign_roles`]) for every joint that moves, in file order.
fn degrees_of_freedom(file: &str, robot: &urdf_rs::Robot) -> Result<Dofs> {
    let mut dof_of_joint: Vec<Option<usize>> = vec![None; robot.joints.len()];
    let mut dofs: Vec<Dof> = Vec::new();
    let mut motions = Vec::with_capacity(robot.joints.len());
    for (j, joint) in robot.joints.iter().enumerate() {
        let motion = motion(file, joint)?;
        motions.push(motion);
        if matches!(motion, Motion::Fixed) {
            continue;
        }
        let name = &joint.name;
        let (lo, hi) = (joint.limit.lower, joint.limit.upper);
        if !(lo.is_finite() && hi.is_finite()) || lo > hi {
            return Err(bad(
                file,
                format!("joint `{name}` has invalid limits [{lo}, {hi}]"),
            ));
        }
        dof_of_joint[j] = Some(dofs.len());
        dofs.push(Dof {
            name: name.clone(),
            joint: j,
            limits: (lo, hi),
            role: Role::Held,
            open: lo,
        });
    }
    Ok(Dofs {
        motions,
        dof_of_joint,
        dofs,
    })
}

/// A joint's `type` and `<axis>`.
fn motion(file: &str, joint: &urdf_rs::Joint) -> Result<Motion> {
    let name = &joint.name;
    let axis = || -> Result<Unit<Vector3<f64>>> {
        let a = Vector3::new(joint.axis.xyz[0], joint.axis.xyz[1], joint.axis.xyz[2]);
        Unit::try_new(a, 1e-12)
            .filter(|_| a.iter().all(|v| v.is_finite()))
            .ok_or_else(|| bad(file, format!("joint `{name}` has a zero or invalid axis")))
    };
    Ok(match joint.joint_type {
        urdf_rs::JointType::Fixed => Motion::Fixed,
        urdf_rs::JointType::Revolute => Motion::Revolute(axis()?),
        urdf_rs::JointType::Prismatic => Motion::Prismatic(axis()?),
        urdf_rs::JointType::Continuous => {
            return Err(bad(
                file,
                format!(
                    "joint `{name}` is continuous: it has no limits, so it has no open and closed ends (make it revolute with limits)"
                ),
            ));
        }
        ref other => {
            return Err(bad(
                file,
                format!(
                    "joint `{name}` has the unsupported type {other:?} (revolute, prismatic and fixed joints are supported)"
                ),
            ));
        }
    })
}

/// Roles and open values of the degrees of freedom: `<mimic>` and the settings' `[joints]`.
fn assign_roles(
    file: &str,
    robot: &urdf_rs::Robot,
    settings: &HandSettings,
    d: &mut Dofs,
) -> Result<()> {
    for (name, _) in settings.joints.iter() {
        if !d.dofs.iter().any(|dof| &dof.name == name) {
            return Err(bad(
                file,
                format!(
                    "settings name the joint `{name}`, which is not a revolute or prismatic joint of the URDF"
                ),
            ));
        }
    }
    for dof in d.dofs.iter_mut() {
        let joint = &robot.joints[dof.joint];
        let s = settings
            .joints
            .get(&joint.name)
            .cloned()
            .unwrap_or_default();
        match &joint.mimic {
            Some(m) => mimic_role(file, robot, &d.dof_of_joint, dof, m, &s)?,
            None => closing_role(file, dof, &s)?,
        }
    }
    let dofs = &mut d.dofs;
    for k in 0..dofs.len() {
        if let Role::Mimic {
            master,
            multiplier,
            offset,
            ..
        } = dofs[k].role
        {
            let v = multiplier * dofs[master].open + offset;
            dofs[k].open = clamp_to(v, dofs[k].limits);
        }
    }
    Ok(())
}

/// The role of a `<mimic>` joint: it follows its joint (which must move and not be a mimic).
fn mimic_role(
    file: &str,
    robot: &urdf_rs::Robot,
    dof_of_joint: &[Option<usize>],
    dof: &mut Dof,
    m: &urdf_rs::Mimic,
    s: &super::JointSettings,
) -> Result<()> {
    let name = &dof.name;
    let master_joint = robot
        .joints
        .iter()
        .position(|o| o.name == m.joint)
        .ok_or_else(|| {
            bad(
                file,
                format!("joint `{name}` mimics `{}`, which is not defined", m.joint),
            )
        })?;
    let master = dof_of_joint[master_joint].ok_or_else(|| {
        bad(
            file,
            format!("joint `{name}` mimics the fixed joint `{}`", m.joint),
        )
    })?;
    if robot.joints[master_joint].mimic.is_some() {
        return Err(bad(
            file,
            format!(
                "joint `{name}` mimics `{}`, which is itself a mimic joint (not supported)",
                m.joint
            ),
        ));
    }
    if s.open.is_some() || s.hold || s.close.is_some() {
        return Err(bad(
            file,
            format!(
                "settings of the mimic joint `{name}`: only `breakaway` applies (it follows `{}`)",
                m.joint
            ),
        ));
    }
    let multiplier = m.multiplier.unwrap_or(1.0);
    let offset = m.offset.unwrap_or(0.0);
    ensure_finite(
        &[multiplier, offset],
        &format!("the mimic of joint `{name}`"),
    )?;
    dof.role = Role::Mimic {
        master,
        multiplier,
        offset,
        breakaway: s.breakaway,
    };
    Ok(())
}

/// The role of a joint that is no mimic: it closes (towards the limit its settings say), or
/// is held; and its open value.
fn closing_role(file: &str, dof: &mut Dof, s: &super::JointSettings) -> Result<()> {
    let name = &dof.name;
    let (lo, hi) = dof.limits;
    if lo >= hi {
        return Err(bad(
            file,
            format!(
                "joint `{name}` has no limits (lower {lo}, upper {hi}): a closing joint needs <limit lower=.. upper=..> with lower < upper"
            ),
        ));
    }
    if s.breakaway {
        return Err(bad(
            file,
            format!("settings: `breakaway` applies to mimic joints only, and `{name}` is not one"),
        ));
    }
    let dir = match s.close.unwrap_or(CloseTowards::Upper) {
        CloseTowards::Upper => 1.0,
        CloseTowards::Lower => -1.0,
    };
    let open = s.open.unwrap_or(if dir > 0.0 || s.hold { lo } else { hi });
    if !(lo..=hi).contains(&open) {
        return Err(bad(
            file,
            format!(
                "settings: the open value {open} of joint `{name}` is outside its limits [{lo}, {hi}]"
            ),
        ));
    }
    dof.role = if s.hold {
        Role::Held
    } else {
        Role::Closing(dir)
    };
    dof.open = open;
    Ok(())
}

/// Each link's finger and the number of fingers: the settings' `fingers`, else the links after
/// the same first moving joint.
fn fingers(
    file: &str,
    settings: &HandSettings,
    link_names: &[String],
    tree: &Tree,
    motions: &[Motion],
) -> Result<(Vec<Option<usize>>, usize)> {
    match &settings.fingers {
        Some(groups) => listed_fingers(file, groups, link_names, tree.root),
        None => Ok(default_fingers(link_names, tree, motions)),
    }
}

/// Fingers as the settings list them.
fn listed_fingers(
    file: &str,
    groups: &[Vec<String>],
    link_names: &[String],
    root: usize,
) -> Result<(Vec<Option<usize>>, usize)> {
    let mut finger_of_link: Vec<Option<usize>> = vec![None; link_names.len()];
    for (f, group) in groups.iter().enumerate() {
        for l in group {
            let i = link_names.iter().position(|n| n == l).ok_or_else(|| {
                bad(
                    file,
                    format!(
                        "settings: finger {} names the link `{l}`, which is not defined",
                        f + 1
                    ),
                )
            })?;
            if i == root {
                return Err(bad(
                    file,
                    format!("settings: the root link `{l}` is the palm, not a finger"),
                ));
            }
            if finger_of_link[i].is_some() {
                return Err(bad(file, format!("settings: link `{l}` is in two fingers")));
            }
            finger_of_link[i] = Some(f);
        }
    }
    Ok((finger_of_link, groups.len()))
}

/// Default fingers: the links after the same first moving joint, numbered in file order of
/// those joints; links fixed to the palm are palm.
fn default_fingers(
    link_names: &[String],
    tree: &Tree,
    motions: &[Motion],
) -> (Vec<Option<usize>>, usize) {
    let first_moving = |link: usize| -> Option<usize> {
        // The first moving joint on the path from the root to `link`.
        let mut found = None;
        let mut l = link;
        while let Some(j) = tree.parent_joint[l] {
            if !matches!(motions[j], Motion::Fixed) {
                found = Some(j);
            }
            l = tree.ends[j].0;
        }
        found
    };
    let mut starts: Vec<usize> = (0..link_names.len()).filter_map(first_moving).collect();
    starts.sort_unstable();
    starts.dedup();
    let finger_of_link = (0..link_names.len())
        .map(|l| first_moving(l).and_then(|j| starts.iter().position(|&s| s == j)))
        .collect();
    (finger_of_link, starts.len())
}

/// `<collision>` elements: the root's first, then the links in file order.
fn collision_bodies(
    file: &str,
    robot: &urdf_rs::Robot,
    root: usize,
    finger_of_link: &[Option<usize>],
) -> Result<Vec<NamedBody>> {
    let mut link_order: Vec<usize> = vec![root];
    link_order.extend((0..robot.links.len()).filter(|&l| l != root));
    let mut bodies = Vec::new();
    for l in link_order {
        let link = &robot.links[l];
        for (k, c) in link.collision.iter().enumerate() {
            let body_name = if k == 0 {
                link.name.clone()
            } else {
                format!("{}#{}", link.name, k + 1)
            };
            let shape = raw_shape(file, &link.name, &c.geometry)?;
            let origin = pose_of(&c.origin);
            ensure_finite(
                origin.to_homogeneous().as_slice(),
                &format!("the collision origin of link `{}`", link.name),
            )?;
            bodies.push((
                Body { link: l, origin },
                body_name,
                finger_of_link[l],
                shape,
            ));
        }
    }
    Ok(bodies)
}

/// A `<collision>`'s `<geometry>`: box, cylinder, sphere or mesh, with positive sizes.
fn raw_shape(file: &str, link: &str, geometry: &urdf_rs::Geometry) -> Result<RawShape> {
    let positive = |v: f64, what: &str| -> Result<f64> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(bad(
                file,
                format!("link `{link}`: collision {what} {v} is not a positive length"),
            ))
        }
    };
    Ok(match geometry {
        urdf_rs::Geometry::Box { size } => RawShape::Ready(LinkShape::Box {
            half_extents: Vector3::new(
                positive(size[0], "box size")? / 2.0,
                positive(size[1], "box size")? / 2.0,
                positive(size[2], "box size")? / 2.0,
            ),
        }),
        urdf_rs::Geometry::Cylinder { radius, length } => RawShape::Ready(LinkShape::Cylinder {
            radius: positive(*radius, "cylinder radius")?,
            half_height: positive(*length, "cylinder length")? / 2.0,
        }),
        urdf_rs::Geometry::Sphere { radius } => RawShape::Ready(LinkShape::Sphere {
            radius: positive(*radius, "sphere radius")?,
        }),
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let scale = scale.map_or([1.0; 3], |s| s.0);
            for s in scale {
                positive(s, "mesh scale")?;
            }
            RawShape::Mesh {
                filename: filename.clone(),
                scale,
            }
        }
        urdf_rs::Geometry::Capsule { .. } => {
            return Err(bad(
                file,
                format!(
                    "link `{link}`: capsule collision geometry is not supported (box, cylinder, sphere and mesh are)"
                ),
            ));
        }
    })
}
