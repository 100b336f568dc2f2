//! [`ElementSet`]: elements of one type behind typed generational handles ([`ElementHandle`]),
//! visited in insertion order, with a revision that every edit bumps. The compliant joints
//! ([`ClearanceJointSet`](crate::rapier::joint::ClearanceJointSet)), the large-step joints
//! ([`LargeStepJointSet`](crate::rapier::large_step::LargeStepJointSet)) and the drives
//! ([`DriveSet`](crate::rapier::sources::drive::DriveSet)) keep their elements in one; a user's
//! own force source can keep its elements in one too.
//!
//! ```
//! use clearance_joint::rapier::pipeline::element_set::ElementSet;
//!
//! let mut springs = ElementSet::new();
//! let a = springs.insert(1.0_f64);
//! let b = springs.insert(2.0);
//! let seen = springs.revision();
//! springs.remove(a);
//! *springs.get_mut(b).unwrap() = 3.0;
//! assert!(springs.get(a).is_none(), "a removed element's handle finds nothing");
//! assert_eq!(springs.iter().map(|(_, v)| *v).collect::<Vec<_>>(), [3.0]);
//! assert!(springs.revision() > seen, "edits are seen by the revision");
//! assert_eq!(b.to_string(), "1v0");
//! ```

use crate::rapier::pipeline::arena::OrderedArena;
use crate::rapier::pipeline::protocol::ElementId;
use rapier3d_f64::data::Index;
use std::marker::PhantomData;

/// Handle of an element of an [`ElementSet<T>`], returned by its
/// [`insert`](ElementSet::insert): generational, as Rapier's `ImpulseJointHandle`. Removing an
/// element never changes another's handle, and the handle of a removed element finds nothing
/// ever after (a later element that reuses its slot gets a new generation). Handles order by
/// slot, not by insertion: iterate the set for the insertion order. Its `Display` is
/// `slot`v`generation`, as bevy's `Entity`.
pub struct ElementHandle<T> {
    index: Index,
    kind: PhantomData<fn() -> T>,
}

impl<T> ElementHandle<T> {
    fn new(index: Index) -> Self {
        ElementHandle {
            index,
            kind: PhantomData,
        }
    }

    /// The handle's slot and generation, untyped: how a guard violation or a stalled contact
    /// names the element.
    pub fn id(self) -> ElementId {
        let (slot, generation) = self.index.into_raw_parts();
        ElementId::from_raw_parts(slot, generation)
    }
}

impl<T> Clone for ElementHandle<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for ElementHandle<T> {}
impl<T> PartialEq for ElementHandle<T> {
    fn eq(&self, other: &Self) -> bool {
        self.index == other.index
    }
}
impl<T> Eq for ElementHandle<T> {}
impl<T> std::hash::Hash for ElementHandle<T> {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.index.hash(state);
    }
}
impl<T> PartialOrd for ElementHandle<T> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl<T> Ord for ElementHandle<T> {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.index.cmp(&other.index)
    }
}
impl<T> std::fmt::Debug for ElementHandle<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ElementHandle({})", self.id())
    }
}

/// `slot`v`generation`, as bevy's `Entity`.
impl<T> std::fmt::Display for ElementHandle<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.id().fmt(f)
    }
}

impl<T> From<ElementHandle<T>> for ElementId {
    fn from(handle: ElementHandle<T>) -> Self {
        handle.id()
    }
}

/// Elements behind [`ElementHandle`]s, visited in insertion order, with a
/// [`revision`](Self::revision) bumped by every insert, remove and mutable access: a
/// [`ClearanceWorld`](crate::rapier::pipeline::world::ClearanceWorld) compares it to notice edits
/// made through its public fields.
#[derive(Clone, Debug)]
pub struct ElementSet<T> {
    elements: OrderedArena<T>,
    revision: u64,
}

impl<T> Default for ElementSet<T> {
    fn default() -> Self {
        ElementSet {
            elements: OrderedArena::default(),
            revision: 0,
        }
    }
}

impl<T> ElementSet<T> {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `element` last; returns its handle.
    pub fn insert(&mut self, element: T) -> ElementHandle<T> {
        self.revision += 1;
        ElementHandle::new(self.elements.insert(element))
    }

    /// Removes the element and returns it (`None` for a handle of no element of this set); the
    /// others keep their handles and their order.
    pub fn remove(&mut self, handle: ElementHandle<T>) -> Option<T> {
        let element = self.elements.remove(handle.index)?;
        self.revision += 1;
        Some(element)
    }

    /// Whether `handle` is an element of this set.
    pub fn contains(&self, handle: ElementHandle<T>) -> bool {
        self.elements.contains(handle.index)
    }

    /// The element behind `handle` (`None` once it was removed).
    pub fn get(&self, handle: ElementHandle<T>) -> Option<&T> {
        self.elements.get(handle.index)
    }

    /// The element behind `handle`, mutably (`None` once it was removed); bumps the revision.
    pub fn get_mut(&mut self, handle: ElementHandle<T>) -> Option<&mut T> {
        self.revision += 1;
        self.elements.get_mut(handle.index)
    }

    /// The elements with their handles, in insertion order.
    pub fn iter(&self) -> impl Iterator<Item = (ElementHandle<T>, &T)> {
        self.elements
            .iter()
            .map(|(i, e)| (ElementHandle::new(i), e))
    }

    /// The elements with their handles, in insertion order, mutably; bumps the revision.
    pub fn iter_mut(&mut self) -> impl Iterator<Item = (ElementHandle<T>, &mut T)> {
        self.revision += 1;
        let handles: Vec<Index> = self.elements.iter().map(|(i, _)| i).collect();
        handles
            .into_iter()
            .zip(self.elements.values_mut())
            .map(|(i, e)| (ElementHandle::new(i), e))
    }

    /// The elements in insertion order.
    pub fn values(&self) -> impl Iterator<Item = &T> {
        self.elements.values()
    }

    /// The elements in insertion order, mutably, for the set's own step hooks: the revision,
    /// which counts the user's edits, stays.
    pub(crate) fn values_mut(&mut self) -> impl Iterator<Item = &mut T> {
        self.elements.values_mut()
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.elements.len()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }

    /// A count that every [`insert`](Self::insert), [`remove`](Self::remove),
    /// [`get_mut`](Self::get_mut) and [`iter_mut`](Self::iter_mut) raises: two equal readings
    /// mean no element was added, removed or edited in between.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Replaces `saved` with `save` of each element, in order (the state before a step that may
    /// be rejected; no allocation after the first call at a given size).
    pub(crate) fn save_into<S>(&self, saved: &mut Vec<S>, save: impl FnMut(&T) -> S) {
        saved.clear();
        saved.extend(self.elements.values().map(save));
    }

    /// Gives each element its state saved by [`save_into`](Self::save_into), in order (the
    /// revision stays: a restore is the step control's, not an edit).
    pub(crate) fn restore_from<S>(&mut self, saved: &[S], mut restore: impl FnMut(&mut T, &S)) {
        for (element, state) in self.elements.values_mut().zip(saved) {
            restore(element, state);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_are_typed_generational_and_edits_raise_the_revision() {
        let mut set = ElementSet::new();
        let [x, y] = ["x", "y"].map(|v| set.insert(v));
        let r = set.revision();
        assert_eq!(set.remove(x), Some("x"));
        assert!(set.revision() > r);
        let z = set.insert("z");
        assert_ne!(z, x, "a reused slot gets a new generation");
        assert!(set.get(x).is_none() && !set.contains(x) && set.remove(x).is_none());
        let r = set.revision();
        let _ = set.iter().count();
        let _ = set.get(y);
        assert_eq!(set.revision(), r, "reading is no edit");
        set.iter_mut().for_each(|(_, v)| *v = "w");
        assert!(set.revision() > r);
        let r = set.revision();
        let _ = set.values_mut().count();
        assert_eq!(set.revision(), r, "the set's own hooks are no edit");
        assert_eq!(format!("{z}"), format!("{}", z.id()));
        assert_eq!(x.id().into_raw_parts(), (0, 0));
        let mut saved = Vec::new();
        set.save_into(&mut saved, |v| v.len());
        assert_eq!(saved, [1, 1]);
    }
}
