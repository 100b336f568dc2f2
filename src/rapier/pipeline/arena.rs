//! The storage behind the joint sets' handles: Rapier's generational
//! [`Arena`](rapier3d_f64::data::Arena) (as behind its `ImpulseJointSet`), plus the insertion
//! order. A handle is an arena [`Index`] (slot and generation): removing a value never changes
//! another's index, and a stale index, whose slot was freed or reused, finds nothing. The values
//! themselves sit in one vector in insertion order, so that the sets visit their joints (and add
//! their forces to a body) in the order they were inserted, whatever was removed in between.

use rapier3d_f64::data::{Arena, Index};

/// Values behind generational indices, visited in insertion order.
#[derive(Clone, Debug)]
pub(crate) struct OrderedArena<T> {
    /// Each live index's position in `items`.
    positions: Arena<usize>,
    /// The values in insertion order, each with its index.
    items: Vec<(Index, T)>,
}

impl<T> Default for OrderedArena<T> {
    fn default() -> Self {
        OrderedArena {
            positions: Arena::new(),
            items: Vec::new(),
        }
    }
}

impl<T> OrderedArena<T> {
    /// Adds `value` last and returns its index.
    pub(crate) fn insert(&mut self, value: T) -> Index {
        let index = self.positions.insert(self.items.len());
        self.items.push((index, value));
        index
    }

    /// Removes the value at `index` (`None` if stale); the others keep their indices and order.
    pub(crate) fn remove(&mut self, index: Index) -> Option<T> {
        let position = self.positions.remove(index)?;
        let (_, value) = self.items.remove(position);
        for (later, _) in &self.items[position..] {
            if let Some(p) = self.positions.get_mut(*later) {
                *p -= 1;
            }
        }
        Some(value)
    }

    /// Whether `index` refers to a value.
    pub(crate) fn contains(&self, index: Index) -> bool {
        self.positions.contains(index)
    }

    /// The value at `index`.
    pub(crate) fn get(&self, index: Index) -> Option<&T> {
        let p = *self.positions.get(index)?;
        self.items.get(p).map(|(_, v)| v)
    }

    /// The value at `index`, mutably.
    pub(crate) fn get_mut(&mut self, index: Index) -> Option<&mut T> {
        let p = *self.positions.get(index)?;
        self.items.get_mut(p).map(|(_, v)| v)
    }

    /// The values with their indices, in insertion order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (Index, &T)> {
        self.items.iter().map(|(i, v)| (*i, v))
    }

    /// The values in insertion order.
    pub(crate) fn values(&self) -> impl Iterator<Item = &T> {
        self.items.iter().map(|(_, v)| v)
    }

    /// The values in insertion order, mutably.
    pub(crate) fn values_mut(&mut self) -> impl Iterator<Item = &mut T> {
        self.items.iter_mut().map(|(_, v)| v)
    }

    /// Number of values.
    pub(crate) fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether there is no value.
    pub(crate) fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removal_keeps_other_indices_and_the_order() {
        let mut a = OrderedArena::default();
        let [x, y, z] = ["x", "y", "z"].map(|v| a.insert(v));
        assert_eq!(a.remove(y), Some("y"));
        assert_eq!((a.get(x), a.get(z)), (Some(&"x"), Some(&"z")));
        assert_eq!(a.values().copied().collect::<Vec<_>>(), ["x", "z"]);
        // The freed slot is reused under a new generation: the stale index finds nothing.
        let w = a.insert("w");
        assert_ne!(w, y);
        assert!(a.get(y).is_none() && !a.contains(y) && a.remove(y).is_none());
        assert_eq!(a.get(w), Some(&"w"));
        // Insertion order, not slot order.
        let order: Vec<_> = a.iter().map(|(i, v)| (i, *v)).collect();
        assert_eq!(order, [(x, "x"), (z, "z"), (w, "w")]);
        *a.get_mut(z).unwrap() = "z2";
        assert_eq!(a.remove(x), Some("x"));
        assert_eq!(a.values().copied().collect::<Vec<_>>(), ["z2", "w"]);
        assert_eq!((a.get(z), a.get(w), a.len()), (Some(&"z2"), Some(&"w"), 2));
    }
}
