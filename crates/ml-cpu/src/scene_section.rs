//! A scene's optional sections: what a feature adds to a scene beyond its objects, lights and
//! camera (the environment light), each a value of the feature's own type that the scene keeps
//! by type (`Sections`); a request for a scene keeps what it asks of each the same way. How a
//! feature's section is read and asked for is its `section_kind::SectionKind`.

use std::any::Any;
use std::fmt::Debug;

/// A value a scene (or a request for one) keeps as a section: plain data of any type.
pub trait Section: Any + Debug + Send + Sync {
    fn clone_section(&self) -> Box<dyn Section>;
    fn same_as(&self, other: &dyn Section) -> bool;
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

impl<T: Any + Clone + Debug + PartialEq + Send + Sync> Section for T {
    fn clone_section(&self) -> Box<dyn Section> {
        Box::new(self.clone())
    }

    fn same_as(&self, other: &dyn Section) -> bool {
        other.as_any().downcast_ref::<T>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// Sections by type, at most one of each.
#[derive(Debug, Default)]
pub struct Sections(Vec<Box<dyn Section>>);

impl Sections {
    /// The section of type `T`, if there is one.
    pub fn get<T: Section>(&self) -> Option<&T> {
        self.0.iter().find_map(|s| s.as_any().downcast_ref::<T>())
    }

    pub fn get_mut<T: Section>(&mut self) -> Option<&mut T> {
        self.0.iter_mut().find_map(|s| s.as_any_mut().downcast_mut::<T>())
    }

    /// Keep `value` as the section of its type (None: remove it).
    pub fn set<T: Section>(&mut self, value: Option<T>) {
        match value {
            Some(value) => self.insert(Box::new(value)),
            None => self.0.retain(|s| !s.as_any().is::<T>()),
        }
    }

    /// Keep a section whose type the caller does not name (a file's table, as its feature read it).
    pub fn insert(&mut self, value: Box<dyn Section>) {
        let id = value.as_any().type_id();
        self.0.retain(|s| s.as_any().type_id() != id);
        self.0.push(value);
    }
}

impl Clone for Sections {
    fn clone(&self) -> Sections {
        Sections(self.0.iter().map(|s| s.clone_section()).collect())
    }
}

/// Equal where each holds the same types with equal values, in any order.
impl PartialEq for Sections {
    fn eq(&self, other: &Sections) -> bool {
        self.0.len() == other.0.len() && self.0.iter().all(|s| other.0.iter().any(|o| s.same_as(o.as_ref())))
    }
}
