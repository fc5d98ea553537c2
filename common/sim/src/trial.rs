//! One simulated grasp trial: place the hand, close it on the object, extract each finger's raw
//! contact cloud and its contacts under every contact model ([`crate::contact::MODELS`]). A trial that touches nothing is a valid outcome
//! with empty clouds (the scorer decides its score).

use nalgebra::Isometry3;

use crate::contact::{
    ContactCloud, ContactModel, ContactModelSettings, ContactPoint, ModelContacts, link_cloud,
};
use crate::error::{Result, ensure_finite};
use crate::hand::{Grasp, Hand, LinkGeometry};
use crate::object::Object;

/// Contacts of one finger (or of the palm).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FingerOutcome {
    /// Finger index, `None` for the palm.
    pub finger: Option<usize>,
    /// Names of the links that make up this finger.
    pub links: Vec<String>,
    /// The raw contact cloud (empty when the finger touches nothing).
    pub cloud: ContactCloud,
    /// Its contacts under each contact model (none when the cloud is empty).
    #[serde(flatten)]
    pub models: ModelContacts,
}

impl FingerOutcome {
    /// A finger's outcome from its raw cloud: every model's contacts computed on `object`,
    /// without noise.
    pub fn from_cloud(
        finger: Option<usize>,
        links: Vec<String>,
        cloud: ContactCloud,
        object: &Object,
        settings: &ContactModelSettings,
    ) -> FingerOutcome {
        let models = ModelContacts::of_cloud(&cloud.points, object, settings);
        FingerOutcome {
            finger,
            links,
            cloud,
            models,
        }
    }

    /// The mean-point contact (`None` when the cloud is empty).
    pub fn mean_point(&self) -> Option<ContactPoint> {
        self.models.get(ContactModel::MeanPoint).first().copied()
    }

    /// Whether this finger touches the object.
    pub fn touches(&self) -> bool {
        !self.cloud.is_empty()
    }

    /// The contacts of the given model.
    pub fn contacts(&self, model: ContactModel) -> Vec<ContactPoint> {
        self.models.get(model).to_vec()
    }
}

/// Everything a trial produced.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrialOutcome {
    /// Object name.
    pub object: String,
    /// The closed hand: joints, link poses, effective palm pose.
    pub grasp: Grasp,
    /// Per finger, in finger order.
    pub fingers: Vec<FingerOutcome>,
    /// The palm's contacts.
    pub palm: FingerOutcome,
    /// Whether anything (a finger or the palm) touches the object; a trial touching nothing has
    /// empty clouds and models everywhere.
    pub touched: bool,
}

impl TrialOutcome {
    /// Whether anything (a finger or the palm) touches the object.
    pub fn touched(&self) -> bool {
        self.touched
    }

    /// Number of fingers (palm excluded) that touch the object.
    pub fn fingers_in_contact(&self) -> usize {
        self.fingers.iter().filter(|f| f.touches()).count()
    }

    /// All contacts of a model, fingers first, then (optionally) the palm.
    pub fn contacts(&self, model: ContactModel, include_palm: bool) -> Vec<ContactPoint> {
        let mut v: Vec<ContactPoint> = self
            .fingers
            .iter()
            .flat_map(|f| f.contacts(model))
            .collect();
        if include_palm {
            v.extend(self.palm.contacts(model));
        }
        v
    }
}

/// Runs one trial: `hand.close(object, palm_pose)`, then contact clouds and models.
///
/// Noise (if configured) is added to the modelled contacts, never to the raw clouds, with one
/// random stream per finger and model derived from the seed
/// ([`crate::contact::noise_stream`]).
pub fn run_trial(
    object: &Object,
    hand: &dyn Hand,
    palm_pose: &Isometry3<f64>,
    settings: &ContactModelSettings,
) -> Result<TrialOutcome> {
    ensure_finite(palm_pose.to_homogeneous().as_slice(), "palm pose")?;
    settings.validate()?;
    let grasp = hand.close(object, palm_pose)?;
    let links = hand.links();
    let geometry = LinkGeometry::new(links);
    let d_c = settings.cloud.contact_distance;
    // Raw points per link (only links within the contact distance are sampled).
    let mut per_link: Vec<Vec<ContactPoint>> = Vec::with_capacity(links.len());
    for (i, pose) in grasp.link_poses.iter().enumerate() {
        let near = grasp.link_distances.get(i).is_some_and(|&d| d <= d_c);
        per_link.push(if near {
            link_cloud(object, &geometry, i, pose, &settings.cloud)?
        } else {
            Vec::new()
        });
    }
    let group = |finger: Option<usize>, stream: u64| -> FingerOutcome {
        let mut names = Vec::new();
        let mut points = Vec::new();
        for (spec, pts) in links.iter().zip(&per_link) {
            if spec.finger == finger {
                names.push(spec.name.clone());
                points.extend_from_slice(pts);
            }
        }
        let mut out =
            FingerOutcome::from_cloud(finger, names, ContactCloud { points }, object, settings);
        if let Some(noise) = &settings.noise {
            out.models.add_noise(noise, stream);
        }
        out
    };
    let fingers: Vec<FingerOutcome> = (0..hand.finger_count())
        .map(|f| group(Some(f), f as u64 + 1))
        .collect();
    let palm = group(None, 0);
    let touched = palm.touches() || fingers.iter().any(FingerOutcome::touches);
    Ok(TrialOutcome {
        object: object.name().to_string(),
        grasp,
        fingers,
        palm,
        touched,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trial_types_can_be_shared_across_threads() {
        fn check<T: Send + Sync>() {}
        check::<Object>();
        check::<crate::hand::BarrettOracle>();
        check::<crate::hand::ParallelJawOracle>();
        check::<Box<dyn Hand>>();
        check::<TrialOutcome>();
        check::<ContactModelSettings>();
    }
}
