//! Assemblies: named instances of parts under affine placements (ISO 10303-44 product
//! structure with ISO 10303-42 item_defined_transformation / mapped_item; IGES 5.3 408
//! singular subfigure instances with 124 transforms).

use super::{AssemblyId, EdgeId, FaceId, Model, ShellId, SolidId, TopologyError};
use crate::nurbs::transform::{Affine, IDENTITY, compose};

/// What an instance places.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// A solid.
    Solid(SolidId),
    /// A shell (a surface model).
    Shell(ShellId),
    /// A single face.
    Face(FaceId),
    /// A free curve (an edge outside any face).
    Edge(EdgeId),
    /// Another assembly.
    Assembly(AssemblyId),
}

/// One use of a part inside an assembly.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// The instance's name (STEP NEXT_ASSEMBLY_USAGE_OCCURRENCE name, IGES label).
    pub name: Option<String>,
    /// Where the part goes: parent coordinates = placement applied to the part's own.
    pub placement: Affine,
    /// The part placed.
    pub part: Part,
}

/// A named set of instances (STEP product with its components; IGES 308 subfigure).
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// The product name.
    pub name: String,
    /// Its components.
    pub instances: Vec<Instance>,
}

/// A leaf of a flattened assembly: a part (never an assembly) in root coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Placed {
    /// The part.
    pub part: Part,
    /// The placement composed from the root down.
    pub placement: Affine,
    /// Instance indices from the root to this leaf.
    pub path: Vec<usize>,
}

impl Model {
    /// Adds an assembly. Its instances may name assemblies added later; [`Model::flatten`]
    /// checks them.
    pub fn add_assembly(&mut self, assembly: Assembly) -> AssemblyId {
        self.assemblies.push(assembly);
        AssemblyId(self.assemblies.len() - 1)
    }

    /// Every leaf part under `root` with its composed placement, depth first in instance
    /// order. Uses an explicit stack (the nesting depth is the file's to choose, so no
    /// recursion), refuses assemblies that contain themselves, and stops at `max_depth`
    /// levels or `max_instances` leaves (a shared sub-assembly multiplies its instances).
    pub fn flatten(
        &self,
        root: AssemblyId,
        max_depth: usize,
        max_instances: usize,
    ) -> Result<Vec<Placed>, TopologyError> {
        let missing = |a: AssemblyId| TopologyError::Missing {
            what: "assembly",
            index: a.0,
        };
        self.assemblies.get(root.0).ok_or_else(|| missing(root))?;
        enum Frame {
            Expand(AssemblyId, Affine, Vec<AssemblyId>, Vec<usize>),
            Leaf(Part, Affine, Vec<usize>),
        }
        let mut out = Vec::new();
        let mut stack = vec![Frame::Expand(root, IDENTITY, vec![root], Vec::new())];
        while let Some(frame) = stack.pop() {
            let (a, placement, chain, path) = match frame {
                Frame::Leaf(part, placement, path) => {
                    if out.len() >= max_instances {
                        return Err(TopologyError::AssemblyTooLarge {
                            root,
                            what: "instances",
                            limit: max_instances,
                        });
                    }
                    out.push(Placed {
                        part,
                        placement,
                        path,
                    });
                    continue;
                }
                Frame::Expand(a, placement, chain, path) => (a, placement, chain, path),
            };
            let asm = self.assemblies.get(a.0).ok_or_else(|| missing(a))?;
            // Pushed in reverse so that they pop in instance order (depth first).
            for (i, inst) in asm.instances.iter().enumerate().rev() {
                let world = compose(&placement, &inst.placement);
                let mut path = path.clone();
                path.push(i);
                match inst.part {
                    Part::Assembly(child) => {
                        let mut chain = chain.clone();
                        chain.push(child);
                        if chain[..chain.len() - 1].contains(&child) {
                            return Err(TopologyError::AssemblyCycle { chain });
                        }
                        if chain.len() > max_depth {
                            return Err(TopologyError::AssemblyTooLarge {
                                root,
                                what: "levels",
                                limit: max_depth,
                            });
                        }
                        stack.push(Frame::Expand(child, world, chain, path));
                    }
                    part => stack.push(Frame::Leaf(part, world, path)),
                }
            }
        }
        Ok(out)
    }
}
