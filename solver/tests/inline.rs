//! The registry of requests that carry their tools inline: it knows no tool, machine or material.

use kerf_solver::capability::Lookup;
use kerf_solver::machine::MachineProfile;
use kerf_solver::material::Material;
use kerf_solver::tool::Tool;

/// No registry: the requests carry their tools inline.
pub struct Inline;

impl Lookup for Inline {
    fn tool(&self, _number: u32) -> Option<Tool> {
        None
    }
    fn machine(&self, _name: &str) -> Option<MachineProfile> {
        None
    }
    fn material(&self, _name: &str) -> Option<Material> {
        None
    }
}
