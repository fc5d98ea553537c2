//! The registry of contact models: [`MODELS`], one row per model with its name, its label, how
//! its contacts are computed from a finger's cloud and its own noise stream. Everything else
//! (`--contacts`, [`ContactModel::ALL`], parsing, a finger's [`ModelContacts`], the noise added
//! to them, the outcome's JSON fields and the contact-model figure of `graspopt experiment
//! metrics`) is read from this table.
//!
//! To add a contact model:
//! 1. a [`ContactModel`] variant (its serde name is its [`ModelEntry::name`]);
//! 2. the function that computes its contacts from a cloud (signature [`ModelFn`]);
//! 3. its row in [`MODELS`], with the next unused [`ModelEntry::noise_key`] (keys are never
//!    reused or renumbered: a model's noisy contacts do not change when another is added).

use crate::error::{Result, SimError};
use crate::object::Object;

use super::{
    ContactModelSettings, ContactPoint, NoiseSettings, add_noise, circular_patch, mean_point,
    surface_model,
};

/// Which contact model to use. Settings files and journals name it as `--contacts` does
/// ([`ContactModel::name`]); the longer names of earlier versions are still read. Its row in
/// [`MODELS`] says everything else about it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactModel {
    /// One contact per finger at the cloud's mean.
    #[serde(rename = "mean", alias = "mean_point")]
    MeanPoint,
    /// Grid points on a disc around the mean, all with the mean normal.
    #[serde(rename = "patch", alias = "circular_patch")]
    CircularPatch,
    /// The surface model of thesis section 2.3.
    Surface,
}

/// How a model's contacts are computed from one finger's raw cloud, on the object, with the
/// models' settings.
pub type ModelFn = fn(&[ContactPoint], &Object, &ContactModelSettings) -> Vec<ContactPoint>;

/// One contact model in the registry.
#[derive(Clone, Copy, Debug)]
pub struct ModelEntry {
    /// The model.
    pub model: ContactModel,
    /// The name users type and see (`--contacts`, settings files, journals).
    pub name: &'static str,
    /// Its name in words (figure legends); with `_` for spaces, its field in a finger's
    /// outcome as JSON.
    pub label: &'static str,
    /// What it is, in one sentence.
    pub about: &'static str,
    /// Its contacts from a cloud.
    pub contacts: ModelFn,
    /// At most one contact per finger, written as that contact or `null` rather than a list.
    pub single: bool,
    /// Names its noise stream ([`noise_stream`]); unique, fixed when the model is added.
    pub noise_key: u64,
}

/// Every contact model, in the order `--help` lists them (the default first).
pub const MODELS: &[ModelEntry] = &[
    ModelEntry {
        model: ContactModel::Surface,
        name: "surface",
        label: "surface",
        about: "the object's surface under a disc around the mean (thesis section 2.3)",
        contacts: surface_model,
        single: false,
        noise_key: 2,
    },
    ModelEntry {
        model: ContactModel::CircularPatch,
        name: "patch",
        label: "circular patch",
        about: "grid points on a disc around the mean, all with the mean normal",
        contacts: |cloud, _, settings| circular_patch(cloud, settings),
        single: false,
        noise_key: 1,
    },
    ModelEntry {
        model: ContactModel::MeanPoint,
        name: "mean",
        label: "mean point",
        about: "one contact per finger at the cloud's mean",
        contacts: |cloud, _, _| mean_point(cloud).into_iter().collect(),
        single: true,
        noise_key: 0,
    },
];

/// How many noise streams the first models number per finger (see [`noise_stream`]).
const FIRST_KEYS: u64 = 3;

/// The random stream of the noise on model `noise_key`'s contacts of one finger (`group`: 0 the
/// palm, `f + 1` finger `f`). The first three models keep the streams of earlier versions,
/// `3 group + key`; a later model's key `k` owns `k * 2^32 + group`, apart from those for any
/// hand of fewer than a billion fingers.
pub fn noise_stream(noise_key: u64, group: u64) -> u64 {
    if noise_key < FIRST_KEYS {
        FIRST_KEYS * group + noise_key
    } else {
        (noise_key << 32) | group
    }
}

impl ContactModel {
    /// Every model, in the order `--help` lists them ([`MODELS`]' order).
    pub const ALL: [ContactModel; MODELS.len()] = {
        let mut all = [ContactModel::Surface; MODELS.len()];
        let mut i = 0;
        while i < MODELS.len() {
            all[i] = MODELS[i].model;
            i += 1;
        }
        all
    };

    /// Its row in [`MODELS`].
    pub fn entry(self) -> &'static ModelEntry {
        &MODELS[self.index()]
    }

    /// Its position in [`MODELS`] (and in a [`ModelContacts`]).
    pub fn index(self) -> usize {
        #[allow(clippy::expect_used)]
        MODELS
            .iter()
            .position(|e| e.model == self)
            .expect("every contact model has a row in MODELS")
    }

    /// A model from its name ([`ContactModel::name`]).
    pub fn parse(name: &str) -> Result<ContactModel> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name.trim())
            .ok_or_else(|| {
                SimError::InvalidInput(format!(
                    "unknown contact model {name:?}: expected {}",
                    names_in_words()
                ))
            })
    }

    /// The name users type and see (`--contacts`): `mean`, `patch`, `surface`.
    pub fn name(self) -> &'static str {
        self.entry().name
    }

    /// Its name in words (`mean point`, `circular patch`, `surface`).
    pub fn label(self) -> &'static str {
        self.entry().label
    }
}

/// `surface, patch or mean`.
fn names_in_words() -> String {
    let names: Vec<&str> = MODELS.iter().map(|e| e.name).collect();
    match names.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

impl std::fmt::Display for ContactModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One finger's contacts under every model, indexed by [`MODELS`]. As JSON, one field per model
/// named after its label, oldest model (smallest noise key) first.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelContacts(Vec<Vec<ContactPoint>>);

impl Default for ModelContacts {
    fn default() -> Self {
        Self(vec![Vec::new(); MODELS.len()])
    }
}

impl ModelContacts {
    /// Every model's contacts of one finger's raw cloud.
    pub fn of_cloud(
        cloud: &[ContactPoint],
        object: &Object,
        settings: &ContactModelSettings,
    ) -> Self {
        Self(
            MODELS
                .iter()
                .map(|e| (e.contacts)(cloud, object, settings))
                .collect(),
        )
    }

    /// The contacts of `model`.
    pub fn get(&self, model: ContactModel) -> &[ContactPoint] {
        &self.0[model.index()]
    }

    /// Adds noise to every model's contacts, each model on its own stream ([`noise_stream`]).
    pub fn add_noise(&mut self, noise: &NoiseSettings, group: u64) {
        for (e, points) in MODELS.iter().zip(&mut self.0) {
            add_noise(points, noise, noise_stream(e.noise_key, group));
        }
    }
}

/// Rows of [`MODELS`] with their positions, oldest model (smallest noise key) first: the
/// order of the thesis, of a finger's JSON fields and of the contact-model figure.
pub fn oldest_first() -> Vec<(usize, &'static ModelEntry)> {
    let mut rows: Vec<_> = MODELS.iter().enumerate().collect();
    rows.sort_by_key(|(_, e)| e.noise_key);
    rows
}

/// A model's JSON field: its label with `_` for spaces.
fn field(e: &ModelEntry) -> String {
    e.label.replace(' ', "_")
}

impl serde::Serialize for ModelContacts {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(MODELS.len()))?;
        for (i, e) in oldest_first() {
            let points = &self.0[i];
            if e.single {
                map.serialize_entry(&field(e), &points.first())?;
            } else {
                map.serialize_entry(&field(e), points)?;
            }
        }
        map.end()
    }
}

impl<'de> serde::Deserialize<'de> for ModelContacts {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_map(FieldsVisitor)
    }
}

/// Reads the fields [`ModelContacts`] writes; a missing field is no contact, other fields are
/// ignored.
struct FieldsVisitor;

impl<'de> serde::de::Visitor<'de> for FieldsVisitor {
    type Value = ModelContacts;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("the contacts of each contact model")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<ModelContacts, A::Error> {
        let mut out = ModelContacts::default();
        while let Some(key) = map.next_key::<String>()? {
            match MODELS.iter().position(|e| field(e) == key) {
                Some(i) if MODELS[i].single => {
                    out.0[i] = map
                        .next_value::<Option<ContactPoint>>()?
                        .into_iter()
                        .collect();
                }
                Some(i) => out.0[i] = map.next_value()?,
                None => {
                    map.next_value::<serde::de::IgnoredAny>()?;
                }
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, Vector3};

    #[test]
    fn a_contact_model_has_one_name_in_flags_files_and_journals() {
        for m in ContactModel::ALL {
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.name()));
            assert_eq!(serde_json::from_str::<ContactModel>(&json).unwrap(), m);
            assert_eq!(ContactModel::parse(m.name()).unwrap(), m);
            assert_eq!(ContactModel::ALL[m.index()], m);
        }
        // Journals and settings files written before still read.
        for (old, m) in [
            ("\"mean_point\"", ContactModel::MeanPoint),
            ("\"circular_patch\"", ContactModel::CircularPatch),
        ] {
            assert_eq!(serde_json::from_str::<ContactModel>(old).unwrap(), m);
        }
        let err = ContactModel::parse("blob").unwrap_err().to_string();
        assert!(err.contains("expected surface, patch or mean"), "{err}");
    }

    #[test]
    fn noise_keys_are_unique_and_the_first_streams_are_the_earlier_versions() {
        let mut keys: Vec<u64> = MODELS.iter().map(|e| e.noise_key).collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), MODELS.len(), "two models share a noise key");
        assert_eq!(noise_stream(0, 0), 0);
        assert_eq!(noise_stream(2, 1), 5);
        assert_eq!(noise_stream(1, 4), 13);
        // A later model never meets the first three's streams.
        let first: Vec<u64> = (0..64)
            .flat_map(|g| (0..3).map(move |k| noise_stream(k, g)))
            .collect();
        for g in 0..64 {
            assert!(!first.contains(&noise_stream(3, g)));
            assert_ne!(noise_stream(3, g), noise_stream(4, g));
        }
    }

    #[test]
    fn a_fingers_contacts_read_back_from_their_json() {
        let p = ContactPoint::new(Point3::new(0.1, 0.0, 0.0), Vector3::x());
        let mut c = ModelContacts::default();
        c.0[ContactModel::MeanPoint.index()] = vec![p];
        c.0[ContactModel::Surface.index()] = vec![p, p];
        let json = serde_json::to_string(&c).unwrap();
        assert!(json.starts_with("{\"mean_point\":{"), "{json}");
        assert!(
            json.contains("\"circular_patch\":[],\"surface\":[{"),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<ModelContacts>(&json).unwrap(), c);
        let none = serde_json::to_string(&ModelContacts::default()).unwrap();
        assert_eq!(
            none,
            "{\"mean_point\":null,\"circular_patch\":[],\"surface\":[]}"
        );
    }
}
