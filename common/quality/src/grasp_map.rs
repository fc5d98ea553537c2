//! The grasp map (thesis eq. 2.13-2.14): every wrench of every contact, expressed about
//! one reference point. Any number of contact points per finger is accepted: a surface
//! model is just more contacts.

use nalgebra::{Dyn, OMatrix, U6};

use crate::contact::{Contact, GraspModel};
use crate::error::QualityError;
use crate::limits::{MAX_COORDINATE, MAX_WRENCHES};
use crate::wrench::Wrench;

/// The set of contact wrenches of a grasp, the columns of `G`.
#[derive(Debug, Clone, PartialEq)]
pub struct GraspMap {
    wrenches: Vec<Wrench>,
}

impl GraspMap {
    /// The grasp map of a list of contacts under a model. Errors name the contact.
    ///
    /// The number of wrenches is bounded by [`MAX_WRENCHES`] (checked before anything
    /// is allocated) and every generated wrench component by [`MAX_COORDINATE`].
    pub fn from_contacts(contacts: &[Contact], model: &GraspModel) -> Result<Self, QualityError> {
        if contacts.is_empty() {
            return Err(QualityError::Empty("contacts"));
        }
        model.validate()?;
        let per_contact = model.contact.wrenches_per_contact();
        let count = contacts.len() as u128 * per_contact as u128;
        if count > MAX_WRENCHES as u128 {
            return Err(QualityError::TooManyContactWrenches {
                contacts: contacts.len(),
                per_contact,
                count,
                limit: MAX_WRENCHES,
            });
        }
        let mut wrenches = Vec::with_capacity(contacts.len() * per_contact);
        for (i, c) in contacts.iter().enumerate() {
            c.validate(i)?;
            let first = wrenches.len();
            model.push_wrenches(c, &mut wrenches);
            if let Some((component, value)) = first_out_of_range(&wrenches[first..]) {
                return Err(QualityError::ContactWrenchOutOfRange {
                    index: i,
                    component,
                    value,
                    limit: MAX_COORDINATE,
                });
            }
        }
        Ok(Self { wrenches })
    }

    /// The grasp map of several fingers, each with its own contact cloud (indices in
    /// errors count contacts across fingers, in order).
    pub fn from_fingers(
        fingers: &[Vec<Contact>],
        model: &GraspModel,
    ) -> Result<Self, QualityError> {
        let all: Vec<Contact> = fingers.iter().flatten().copied().collect();
        Self::from_contacts(&all, model)
    }

    /// A grasp map given directly as wrenches; errors on an empty set, a non-finite or
    /// out-of-range wrench, or more than [`MAX_WRENCHES`].
    pub fn from_wrenches(wrenches: Vec<Wrench>) -> Result<Self, QualityError> {
        check_wrenches(&wrenches)?;
        Ok(Self { wrenches })
    }

    /// The wrenches.
    pub fn wrenches(&self) -> &[Wrench] {
        &self.wrenches
    }

    /// `G` as a 6 x m matrix.
    pub fn matrix(&self) -> OMatrix<f64, U6, Dyn> {
        OMatrix::<f64, U6, Dyn>::from_columns(&self.wrenches)
    }
}

/// Errors on an empty wrench set, more than [`MAX_WRENCHES`] wrenches, or a wrench
/// with a NaN or infinite component or one beyond [`MAX_COORDINATE`] in absolute value.
pub fn check_wrenches(wrenches: &[Wrench]) -> Result<(), QualityError> {
    if wrenches.is_empty() {
        return Err(QualityError::Empty("wrenches"));
    }
    if wrenches.len() > MAX_WRENCHES {
        return Err(QualityError::TooManyWrenches {
            count: wrenches.len(),
            limit: MAX_WRENCHES,
        });
    }
    for (index, w) in wrenches.iter().enumerate() {
        if !w.iter().all(|x| x.is_finite()) {
            return Err(QualityError::WrenchNotFinite {
                index,
                value: [w[0], w[1], w[2], w[3], w[4], w[5]],
            });
        }
        if let Some((component, value)) = first_out_of_range(std::slice::from_ref(w)) {
            return Err(QualityError::WrenchOutOfRange {
                index,
                component,
                value,
                limit: MAX_COORDINATE,
            });
        }
    }
    Ok(())
}

/// The first component (index within its wrench, value) of `wrenches` that is NaN,
/// infinite or beyond [`MAX_COORDINATE`] in absolute value.
fn first_out_of_range(wrenches: &[Wrench]) -> Option<(usize, f64)> {
    wrenches.iter().find_map(|w| {
        w.iter()
            .enumerate()
            .find(|(_, x)| !x.is_finite() || x.abs() > MAX_COORDINATE)
            .map(|(k, &x)| (k, x))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::FrictionModel;
    use nalgebra::Vector3;

    #[test]
    fn one_frictionless_contact_gives_its_normal_and_moment() {
        let model = GraspModel::new(FrictionModel::Frictionless);
        let c = Contact::new(Vector3::new(0.0, 1.0, 0.0), Vector3::x());
        let g = GraspMap::from_contacts(&[c], &model).unwrap();
        assert_eq!(g.wrenches().len(), 1);
        let expected = Wrench::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
        assert!((g.wrenches()[0] - expected).norm() < 1e-15);
        assert_eq!(g.matrix().ncols(), 1);
    }

    #[test]
    fn errors_name_the_bad_contact() {
        let model = GraspModel::new(FrictionModel::Frictionless);
        let good = Contact::new(Vector3::zeros(), Vector3::z());
        let bad = Contact::new(Vector3::zeros(), Vector3::zeros());
        assert_eq!(
            GraspMap::from_fingers(&[vec![good], vec![good, bad]], &model),
            Err(QualityError::ZeroNormal { index: 2 })
        );
        assert_eq!(
            GraspMap::from_contacts(&[], &model),
            Err(QualityError::Empty("contacts"))
        );
        assert!(GraspMap::from_wrenches(vec![Wrench::repeat(f64::NAN)]).is_err());
    }
}
