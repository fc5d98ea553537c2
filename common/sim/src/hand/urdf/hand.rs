//! The hand built from a parsed URDF description: its kinematics, closing and links.

use super::*;

/// A hand built from a URDF description: see the module doc.
#[derive(Debug)]
pub struct UrdfHand {
    name: String,
    file: String,
    pub(super) links: Vec<LinkSpec>,
    bodies: Vec<Body>,
    pub(super) joints: Vec<JointModel>,
    pub(super) dofs: Vec<Dof>,
    link_count: usize,
    pub(super) finger_count: usize,
    /// The root link's frame in the palm frame: turned by `rz_degrees` about the approach axis
    /// (`None` when not turned, so that the hand's poses are exactly the URDF's).
    mount: Option<Isometry3<f64>>,
    /// The turn of `mount` (radians).
    pub(super) rz: f64,
    geometry: LinkGeometry,
    /// `levers[d][b]`: bound on how far a point of body `b` moves per unit of dof `d` (when the
    /// dof moves the body).
    levers: Vec<Vec<Option<f64>>>,
}

impl UrdfHand {
    /// A hand from a parsed description; mesh file names are resolved against `mesh_dir` (a hand
    /// with meshes and no folder is an error naming the first mesh).
    pub fn new(desc: HandDescription, mesh_dir: Option<&Path>) -> Result<Self> {
        let mut links = Vec::with_capacity(desc.bodies.len());
        let mut bodies = Vec::with_capacity(desc.bodies.len());
        for (body, name, finger, raw) in desc.bodies {
            let link = &desc.link_names[body.link];
            let shape = match raw {
                RawShape::Ready(s) => s,
                RawShape::Mesh { filename, scale } => {
                    let dir = mesh_dir.ok_or_else(|| {
                        bad(
                            &desc.file,
                            format!("link `{link}`: the mesh `{filename}` has no folder to be found in (load the URDF from a file)"),
                        )
                    })?;
                    LinkShape::Mesh {
                        mesh: load_link_mesh(
                            &filename,
                            &resolve_mesh(&filename, dir),
                            scale,
                            link,
                            &desc.file,
                        )?,
                    }
                }
            };
            links.push(LinkSpec {
                name,
                finger,
                shape,
            });
            bodies.push(body);
        }
        let geometry = LinkGeometry::new(&links);
        let mut hand = Self {
            name: desc.name,
            file: desc.file,
            links,
            bodies,
            joints: desc.joints,
            dofs: desc.dofs,
            link_count: desc.link_names.len(),
            finger_count: desc.finger_count,
            mount: (desc.rz != 0.0).then(|| {
                Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), desc.rz),
                )
            }),
            rz: desc.rz,
            geometry,
            levers: Vec::new(),
        };
        hand.levers = hand.compute_levers();
        Ok(hand)
    }

    /// Parses URDF text (and optional settings text) without touching files; meshes are looked
    /// up in `mesh_dir`. `file` names the hand in errors.
    pub fn from_strs(
        file: &str,
        urdf: &str,
        settings: Option<&str>,
        mesh_dir: Option<&Path>,
    ) -> Result<Self> {
        // Errors in the settings name their file: the one beside the URDF, same stem.
        let settings_file = Path::new(file).with_extension("toml").display().to_string();
        let settings = settings
            .map(|s| HandSettings::parse(s, &settings_file))
            .transpose()?;
        Self::new(
            HandDescription::parse(file, urdf, settings.as_ref())?,
            mesh_dir,
        )
    }

    /// Reads a URDF file, the settings file beside it (same stem, `.toml`) if there is one, and
    /// its meshes.
    pub fn from_file(path: &Path) -> Result<Self> {
        let file = path.display().to_string();
        let urdf = std::fs::read_to_string(path)
            .map_err(|e| bad(&file, format!("cannot read it: {e}")))?;
        let toml_path = path.with_extension("toml");
        let settings = if toml_path.is_file() {
            Some(std::fs::read_to_string(&toml_path).map_err(|e| {
                bad(
                    &toml_path.display().to_string(),
                    format!("cannot read it: {e}"),
                )
            })?)
        } else {
            None
        };
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_strs(&file, &urdf, settings.as_deref(), Some(&dir))
    }

    /// The file (or built-in source) the hand was read from.
    pub fn source(&self) -> &str {
        &self.file
    }

    /// Which degrees of freedom close (their names), in closing order.
    pub fn closing_joints(&self) -> Vec<String> {
        self.closing_order()
            .into_iter()
            .map(|d| self.dofs[d].name.clone())
            .collect()
    }

    fn closing_order(&self) -> Vec<usize> {
        self.joints
            .iter()
            .filter_map(|j| j.dof)
            .filter(|&d| matches!(self.dofs[d].role, Role::Closing(_)))
            .collect()
    }

    /// Link frames (indexed by link) in the palm frame for the joint values `q`.
    fn link_frames(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        let mut frames = vec![Isometry3::identity(); self.link_count];
        // The root is the only link no joint sets; joints come parents first.
        for j in &self.joints {
            let motion = match (j.motion, j.dof) {
                (Motion::Revolute(axis), Some(d)) => Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&axis, q[d]),
                ),
                (Motion::Prismatic(axis), Some(d)) => Isometry3::from_parts(
                    Translation3::from(axis.into_inner() * q[d]),
                    UnitQuaternion::identity(),
                ),
                _ => Isometry3::identity(),
            };
            frames[j.child] = frames[j.parent] * j.origin * motion;
        }
        frames
    }

    /// Body frames in the palm frame for the joint values `q` (turned by `rz_degrees`).
    pub(super) fn body_poses(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        let frames = self.link_frames(q);
        self.bodies
            .iter()
            .map(|b| match &self.mount {
                Some(m) => m * frames[b.link] * b.origin,
                None => frames[b.link] * b.origin,
            })
            .collect()
    }

    /// The palm's turn about its approach axis (radians; the settings' `rz_degrees`).
    pub fn rz(&self) -> f64 {
        self.rz
    }

    /// For each dof and body: a bound on how far any point of the body moves per unit of the
    /// dof's value, whatever the other joints do (`None` when the dof does not move the body).
    ///
    /// Revolute dof: the distance from its axis's origin to the farthest point of the body,
    /// bounded by the lengths of the joint offsets between them (plus the travel of prismatic
    /// joints) and the farthest point of the body from the last moving joint's frame.
    /// Prismatic dof: 1.
    fn compute_levers(&self) -> Vec<Vec<Option<f64>>> {
        // The joint (index into self.joints) whose child each link is.
        let mut joint_of_link: Vec<Option<usize>> = vec![None; self.link_count];
        for (k, j) in self.joints.iter().enumerate() {
            joint_of_link[j.child] = Some(k);
        }
        let mut levers = vec![vec![None; self.bodies.len()]; self.dofs.len()];
        for (b, body) in self.bodies.iter().enumerate() {
            // Joints from the body's link up to the root (nearest first).
            let mut path = Vec::new();
            let mut l = body.link;
            while let Some(k) = joint_of_link[l] {
                path.push(k);
                l = self.joints[k].parent;
            }
            for (pos, &k) in path.iter().enumerate() {
                let Some(d) = self.joints[k].dof else {
                    continue;
                };
                levers[d][b] = Some(match self.joints[k].motion {
                    Motion::Prismatic(_) => 1.0,
                    _ => {
                        // Joints after k towards the body: path[..pos], farthest first.
                        let after: Vec<usize> = path[..pos].iter().rev().copied().collect();
                        let last_moving = after
                            .iter()
                            .rposition(|&a| !matches!(self.joints[a].motion, Motion::Fixed));
                        let mut sum = 0.0;
                        let upto = last_moving.map_or(0, |i| i + 1);
                        for &a in &after[..upto] {
                            sum += self.joints[a].origin.translation.vector.norm();
                            if let (Motion::Prismatic(_), Some(da)) =
                                (self.joints[a].motion, self.joints[a].dof)
                            {
                                let (lo, hi) = self.dofs[da].limits;
                                sum += lo.abs().max(hi.abs());
                            }
                        }
                        // The body's frame in the last moving joint's child frame.
                        let mut rigid = Isometry3::identity();
                        for &a in &after[upto..] {
                            rigid *= self.joints[a].origin;
                        }
                        rigid *= body.origin;
                        let joint_in_body = rigid.inverse_transform_point(&Point3::origin());
                        sum + self.links[b].shape.farthest_from(&joint_in_body)
                    }
                });
            }
        }
        levers
    }

    /// The joints that mimic dof `a` and still follow it: `(dof, multiplier, offset,
    /// breakaway)`.
    fn followers(&self, a: usize, detached: &[bool]) -> Vec<(usize, f64, f64, bool)> {
        self.dofs
            .iter()
            .enumerate()
            .filter_map(|(f, d)| match d.role {
                Role::Mimic {
                    master,
                    multiplier,
                    offset,
                    breakaway,
                } if master == a && !detached[f] => Some((f, multiplier, offset, breakaway)),
                _ => None,
            })
            .collect()
    }

    /// The bodies that dof `a` and its `followers` move, each with how far it moves per unit of
    /// `a` at most.
    fn moved_bodies(&self, a: usize, followers: &[(usize, f64, f64, bool)]) -> Vec<(usize, f64)> {
        let mut moved: Vec<(usize, f64)> = Vec::new();
        for b in 0..self.bodies.len() {
            let mut rate = 0.0;
            let mut moves = false;
            let movers =
                std::iter::once((a, 1.0)).chain(followers.iter().map(|&(f, m, _, _)| (f, m)));
            for (j, m) in movers {
                if let Some(l) = self.levers[j][b] {
                    rate += m.abs() * l;
                    moves = true;
                }
            }
            if moves {
                moved.push((b, rate));
            }
        }
        moved
    }

    /// Advances dof `a` (with the joints that mimic it) towards its closed limit until one of
    /// the bodies it moves touches the object or it reaches the limit; then releases its
    /// breakaway followers. `dir`: +1 towards the upper limit, -1 towards the lower.
    fn advance(
        &self,
        object: &Object,
        palm: &Isometry3<f64>,
        q: &mut Vec<f64>,
        detached: &mut [bool],
        a: usize,
        dir: f64,
    ) -> Result<()> {
        let followers = self.followers(a, detached);
        let moved = self.moved_bodies(a, &followers);
        let (lo, hi) = self.dofs[a].limits;
        let config = |base: &[f64], t: f64| -> Vec<f64> {
            let mut c = base.to_vec();
            c[a] = dir * t;
            for &(f, m, off, _) in &followers {
                c[f] = clamp_to(m * c[a] + off, self.dofs[f].limits);
            }
            c
        };
        let t0 = dir * q[a];
        let t1 = (dir * if dir > 0.0 { hi } else { lo }).max(t0);
        let touched = if moved.is_empty() {
            *q = config(q, t1);
            None
        } else {
            let rates: Vec<f64> = moved.iter().map(|m| m.1).collect();
            let base = q.clone();
            let adv = advance_until_contact(
                |t| {
                    let poses = self.body_poses(&config(&base, t));
                    moved
                        .iter()
                        .map(|&(b, _)| {
                            self.geometry
                                .distance_g(object, b, &iso2pose(&(palm * poses[b])), 0.05)
                        })
                        .collect()
                },
                t0,
                t1,
                &rates,
            )?;
            *q = config(&base, adv.t);
            adv.touched.map(|k| moved[k].0)
        };
        for &(f, m, _, breakaway) in &followers {
            // A follower continues alone unless the link that stopped its joint is its own.
            if !breakaway || touched.is_some_and(|b| self.levers[f][b].is_some()) {
                continue;
            }
            detached[f] = true;
            self.advance(object, palm, q, detached, f, dir * m.signum())?;
        }
        Ok(())
    }
}

impl Hand for UrdfHand {
    fn name(&self) -> &str {
        &self.name
    }

    fn links(&self) -> &[LinkSpec] {
        &self.links
    }

    fn finger_count(&self) -> usize {
        self.finger_count
    }

    /// The revolute and prismatic joints, in URDF file order.
    fn joint_names(&self) -> Vec<String> {
        self.dofs.iter().map(|d| d.name.clone()).collect()
    }

    fn joint_limits(&self) -> Vec<(f64, f64)> {
        self.dofs.iter().map(|d| d.limits).collect()
    }

    fn open_configuration(&self) -> Vec<f64> {
        self.dofs.iter().map(|d| d.open).collect()
    }

    fn link_poses(&self, joints: &[f64]) -> Result<Vec<Isometry3<f64>>> {
        if joints.len() != self.dofs.len() {
            return Err(SimError::InvalidInput(format!(
                "hand `{}` needs {} joint values, got {}",
                self.name,
                self.dofs.len(),
                joints.len()
            )));
        }
        ensure_finite(joints, "joint values")?;
        Ok(self.body_poses(joints))
    }

    fn close(&self, object: &Object, palm_pose: &Isometry3<f64>) -> Result<Grasp> {
        let (palm, retreat) = clear_hand(self, &self.geometry, object, palm_pose)?;
        let mut q = self.open_configuration();
        let mut detached = vec![false; self.dofs.len()];
        for a in self.closing_order() {
            let Role::Closing(dir) = self.dofs[a].role else {
                continue;
            };
            self.advance(object, &palm, &mut q, &mut detached, a, dir)?;
        }
        finish_grasp(self, &self.geometry, object, palm_pose, palm, retreat, q)
    }
}
