//! Typed records of the ISO 10303-42 geometry that is not a B-spline (placements,
//! directions, vectors, the analytic and composite curves, the elementary and swept
//! surfaces) and of the topology that bounds an edge curve or a face surface (clause 5).
//!
//! Attributes are read by name from the tables of [`super::schema`] (`OWN_ATTRIBUTES`,
//! `SUPERTYPE_CHAINS`), so simple and complex instances read the same. A record checks
//! what the EXPRESS *types* require (a REAL radius, a reference, a BOOLEAN); geometric
//! rules (radius > 0, a non-zero direction) are the exchange layer's job.

use std::borrow::Cow;

use super::ast::{Body, Instance, Parameter};
use super::error::SchemaError;
use super::scan::{RawInstance, Scanned};
use super::schema::{At, Attributes, DecodeError, Logical, canonical_name, render};
use super::string::StepString;

/// `trimming_select` (ISO 10303-42 4.3.?, `SELECT (cartesian_point, parameter_value)`): one
/// element of a TRIMMED_CURVE's `trim_1`/`trim_2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrimmingSelect {
    /// `PARAMETER_VALUE(t)`: a value of the basis curve's parameter (an angle in the
    /// file's plane-angle unit for a conic).
    Parameter(f64),
    /// A reference to a CARTESIAN_POINT on the basis curve.
    Point(u64),
}

/// A DIRECTION's `direction_ratios` (ISO 10303-42 4.4.3: `LIST [2:3] OF REAL`), held
/// inline: a file has hundreds of thousands of directions, and a vector each was an
/// allocation each. Up to three are held (fewer than two are the reader's to refuse where
/// the direction is used); a longer list is a schema error of the DIRECTION.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Ratios {
    len: u8,
    values: [f64; 3],
}

impl Ratios {
    /// The ratios `values`; `None` for more than three.
    pub fn new(values: &[f64]) -> Option<Self> {
        let mut r = Ratios::default();
        for &v in values {
            r.push(v)?;
        }
        Some(r)
    }

    /// Appends `v`; `None` when three are held already.
    pub fn push(&mut self, v: f64) -> Option<()> {
        *self.values.get_mut(usize::from(self.len))? = v;
        self.len += 1;
        Some(())
    }
}

impl std::ops::Deref for Ratios {
    type Target = [f64];

    fn deref(&self) -> &[f64] {
        self.values.get(..usize::from(self.len)).unwrap_or_default()
    }
}

/// The trimming attributes of a `trimmed_curve` (ISO 10303-42 4.4.21).
#[derive(Debug, Clone, PartialEq)]
pub struct Trimming<'a> {
    /// `trim_1`: one or two trimming selects (a point and/or a parameter).
    pub trim_1: Box<[TrimmingSelect]>,
    /// `trim_2`.
    pub trim_2: Box<[TrimmingSelect]>,
    /// `sense_agreement`.
    pub sense_agreement: bool,
    /// `master_representation` without dots (`PARAMETER`, `CARTESIAN`, `UNSPECIFIED`).
    pub master_representation: &'a str,
}

/// The trimming attributes of a `rectangular_trimmed_surface` (ISO 10303-42 4.4.50).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RectangularTrim {
    /// `u1`.
    pub u1: f64,
    /// `u2`.
    pub u2: f64,
    /// `v1`.
    pub v1: f64,
    /// `v2`.
    pub v2: f64,
    /// `usense`.
    pub usense: bool,
    /// `vsense`.
    pub vsense: bool,
}

/// A list of instance references held inline up to two (one allocation less per list
/// for the commonest lists of a B-rep file); a slice by `Deref`.
pub type Refs = smallvec::SmallVec<[u64; 2]>;

/// One ISO 10303-42 entity of those this module reads; each variant carries its explicit
/// attributes under their EXPRESS names (inherited `position`/`location` included).
#[derive(Debug, Clone, PartialEq)]
pub enum GeometryRecord<'a> {
    /// `direction` (4.4.3): `direction_ratios`, 2 or 3 of them.
    Direction {
        /// `direction_ratios`.
        direction_ratios: Ratios,
    },
    /// `vector` (4.4.4): `orientation` (a DIRECTION), `magnitude` (>= 0).
    Vector {
        /// `orientation`.
        orientation: u64,
        /// `magnitude`.
        magnitude: f64,
    },
    /// `axis1_placement` (4.4.6): `location`, optional `axis`.
    Axis1Placement {
        /// `location` (a CARTESIAN_POINT).
        location: u64,
        /// `axis` (a DIRECTION), `None` for `$` (then (0,0,1)).
        axis: Option<u64>,
    },
    /// `axis2_placement_2d` (4.4.7): `location`, optional `ref_direction`.
    Axis2Placement2d {
        /// `location`.
        location: u64,
        /// `ref_direction`.
        ref_direction: Option<u64>,
    },
    /// `axis2_placement_3d` (4.4.8): `location`, optional `axis` and `ref_direction`.
    Axis2Placement3d {
        /// `location`.
        location: u64,
        /// `axis`.
        axis: Option<u64>,
        /// `ref_direction`.
        ref_direction: Option<u64>,
    },
    /// `line` (4.4.11): `pnt`, `dir` (a VECTOR).
    Line {
        /// `pnt`.
        pnt: u64,
        /// `dir`.
        dir: u64,
    },
    /// `circle` (4.4.14): `position`, `radius`.
    Circle {
        /// `position` (an AXIS2_PLACEMENT_2D or _3D).
        position: u64,
        /// `radius`.
        radius: f64,
    },
    /// `ellipse` (4.4.15): `position`, `semi_axis_1`, `semi_axis_2`.
    Ellipse {
        /// `position`.
        position: u64,
        /// `semi_axis_1` (along the placement's x).
        semi_axis_1: f64,
        /// `semi_axis_2`.
        semi_axis_2: f64,
    },
    /// `hyperbola` (4.4.16): `position`, `semi_axis`, `semi_imag_axis`.
    Hyperbola {
        /// `position`.
        position: u64,
        /// `semi_axis`.
        semi_axis: f64,
        /// `semi_imag_axis`.
        semi_imag_axis: f64,
    },
    /// `parabola` (4.4.17): `position`, `focal_dist`.
    Parabola {
        /// `position`.
        position: u64,
        /// `focal_dist`.
        focal_dist: f64,
    },
    /// `polyline` (4.4.19): `points`.
    Polyline {
        /// `points` (CARTESIAN_POINTs, at least 2).
        points: Vec<u64>,
    },
    /// `trimmed_curve` (4.4.21).
    TrimmedCurve {
        /// `basis_curve`.
        basis_curve: u64,
        /// The other attributes, boxed: the entity is rare, and its attributes inline would
        /// make every record (the variants share one size) half as large again.
        trimming: Box<Trimming<'a>>,
    },
    /// `composite_curve` (4.4.22): `segments`, `self_intersect`.
    CompositeCurve {
        /// `segments` (COMPOSITE_CURVE_SEGMENTs).
        segments: Vec<u64>,
        /// `self_intersect`.
        self_intersect: Logical,
    },
    /// `composite_curve_segment` (4.4.23): `transition`, `same_sense`, `parent_curve`.
    CompositeCurveSegment {
        /// `transition` without dots (`CONTINUOUS`, `DISCONTINUOUS`...).
        transition: &'a str,
        /// `same_sense`.
        same_sense: bool,
        /// `parent_curve`.
        parent_curve: u64,
    },
    /// `surface_curve` (4.4.27) and its subtypes `seam_curve`, `intersection_curve`.
    SurfaceCurve {
        /// `curve_3d`.
        curve_3d: u64,
        /// `associated_geometry` (PCURVEs or surfaces, 1 or 2). A boxed slice, not a
        /// vector or an inline [`Refs`]: this record is common, and sets the size of all of
        /// them.
        associated_geometry: Box<[u64]>,
        /// `master_representation` without dots (`CURVE_3D`, `PCURVE_S1`, `PCURVE_S2`).
        master_representation: &'a str,
    },
    /// `pcurve` (4.4.26): `basis_surface`, `reference_to_curve`.
    Pcurve {
        /// `basis_surface`.
        basis_surface: u64,
        /// `reference_to_curve` (a DEFINITIONAL_REPRESENTATION).
        reference_to_curve: u64,
    },
    /// `definitional_representation` (ISO 10303-43): `items`, `context_of_items`.
    DefinitionalRepresentation {
        /// `items` (one 2-D curve in the files of every CAD system seen: held inline).
        items: Refs,
        /// `context_of_items`.
        context_of_items: u64,
    },
    /// `plane` (4.4.32): `position`.
    Plane {
        /// `position` (an AXIS2_PLACEMENT_3D).
        position: u64,
    },
    /// `cylindrical_surface` (4.4.33): `position`, `radius`.
    CylindricalSurface {
        /// `position`.
        position: u64,
        /// `radius`.
        radius: f64,
    },
    /// `conical_surface` (4.4.34): `position`, `radius`, `semi_angle`.
    ConicalSurface {
        /// `position`.
        position: u64,
        /// `radius` at v = 0.
        radius: f64,
        /// `semi_angle`, in the file's plane-angle unit.
        semi_angle: f64,
    },
    /// `spherical_surface` (4.4.35): `position`, `radius`.
    SphericalSurface {
        /// `position`.
        position: u64,
        /// `radius`.
        radius: f64,
    },
    /// `toroidal_surface` (4.4.36) and `degenerate_toroidal_surface` (4.4.37).
    ToroidalSurface {
        /// `position`.
        position: u64,
        /// `major_radius`.
        major_radius: f64,
        /// `minor_radius`.
        minor_radius: f64,
        /// `select_outer` of a DEGENERATE_TOROIDAL_SURFACE, `None` for a plain torus.
        select_outer: Option<bool>,
    },
    /// `surface_of_linear_extrusion` (4.4.40): `swept_curve`, `extrusion_axis`.
    SurfaceOfLinearExtrusion {
        /// `swept_curve`.
        swept_curve: u64,
        /// `extrusion_axis` (a VECTOR).
        extrusion_axis: u64,
    },
    /// `surface_of_revolution` (4.4.41): `swept_curve`, `axis_position`.
    SurfaceOfRevolution {
        /// `swept_curve`.
        swept_curve: u64,
        /// `axis_position` (an AXIS1_PLACEMENT).
        axis_position: u64,
    },
    /// `rectangular_trimmed_surface` (4.4.50).
    RectangularTrimmedSurface {
        /// `basis_surface`.
        basis_surface: u64,
        /// The trimming parameters, boxed (a rare entity; see
        /// [`GeometryRecord::TrimmedCurve`]).
        bounds: Box<RectangularTrim>,
    },
    /// `offset_curve_2d`/`offset_curve_3d`/`offset_surface` (4.4.24, 4.4.25, 4.4.46): no
    /// exact rational form in general; read so the reader can name what it refuses.
    Offset {
        /// `basis_curve` or `basis_surface`.
        basis: u64,
    },
    /// `vertex_point` (5.4.3): `vertex_geometry`.
    VertexPoint {
        /// `vertex_geometry` (a POINT).
        vertex_geometry: u64,
    },
    /// `edge_curve` (5.4.6): `edge_start`, `edge_end`, `edge_geometry`, `same_sense`.
    EdgeCurve {
        /// `edge_start` (a VERTEX).
        edge_start: u64,
        /// `edge_end`.
        edge_end: u64,
        /// `edge_geometry`.
        edge_geometry: u64,
        /// `same_sense`.
        same_sense: bool,
    },
    /// `oriented_edge` (5.4.7): `edge_element`, `orientation`.
    OrientedEdge {
        /// `edge_element`.
        edge_element: u64,
        /// `orientation`.
        orientation: bool,
    },
    /// `edge_loop` (5.4.15): `edge_list` (of PATH).
    EdgeLoop {
        /// `edge_list` (ORIENTED_EDGEs).
        edge_list: Vec<u64>,
    },
    /// `face_bound` (5.4.19) and `face_outer_bound` (5.4.20): `bound`, `orientation`.
    FaceBound {
        /// `bound` (a LOOP).
        bound: u64,
        /// `orientation`.
        orientation: bool,
    },
    /// `face_surface` (5.4.22) and `advanced_face` (5.4.23): `bounds`, `face_geometry`,
    /// `same_sense`.
    FaceSurface {
        /// `bounds` (FACE_BOUNDs; one or two on most faces: held inline).
        bounds: Refs,
        /// `face_geometry`.
        face_geometry: u64,
        /// `same_sense`.
        same_sense: bool,
    },
    /// `vertex_loop` (ISO 10303-42 5.4, vertex_loop): a loop of one vertex (a face's
    /// degenerate boundary, e.g. a cone's apex).
    VertexLoop {
        /// `loop_vertex`.
        loop_vertex: u64,
    },
    /// `poly_loop` (ISO 10303-42 5.4, poly_loop): a loop of straight edges through points.
    PolyLoop {
        /// `polygon` (CARTESIAN_POINTs, at least 3).
        polygon: Vec<u64>,
    },
    /// `open_shell` and `closed_shell` (ISO 10303-42 5.4, connected_face_set subtypes):
    /// `cfs_faces`.
    Shell {
        /// `cfs_faces` (FACEs).
        cfs_faces: Vec<u64>,
        /// `true` for CLOSED_SHELL.
        closed: bool,
    },
    /// `oriented_face` (ISO 10303-42 5.4): `face_element`, `orientation` (`bounds` is
    /// derived).
    OrientedFace {
        /// `face_element`.
        face_element: u64,
        /// `orientation`.
        orientation: bool,
    },
    /// `oriented_closed_shell` (ISO 10303-42 5.4): `closed_shell_element`, `orientation`
    /// (`cfs_faces` is derived).
    OrientedClosedShell {
        /// `closed_shell_element`.
        closed_shell_element: u64,
        /// `orientation`.
        orientation: bool,
    },
    /// `manifold_solid_brep` and `brep_with_voids` (ISO 10303-42 clause 6): `outer` and
    /// the `voids` (ORIENTED_CLOSED_SHELLs; empty for a MANIFOLD_SOLID_BREP).
    ManifoldSolidBrep {
        /// `outer` (a CLOSED_SHELL).
        outer: u64,
        /// `voids`.
        voids: Vec<u64>,
    },
    /// `shell_based_surface_model` (ISO 10303-42 clause 6): `sbsm_boundary`.
    ShellBasedSurfaceModel {
        /// `sbsm_boundary` (OPEN_SHELLs or CLOSED_SHELLs).
        sbsm_boundary: Vec<u64>,
    },
    /// `face_based_surface_model` (ISO 10303-42 clause 6): `fbsm_faces`.
    FaceBasedSurfaceModel {
        /// `fbsm_faces` (CONNECTED_FACE_SETs).
        fbsm_faces: Vec<u64>,
    },
    /// `geometric_set` and `geometric_curve_set` (ISO 10303-42 clause 6): `elements`.
    GeometricSet {
        /// `elements` (points, curves, surfaces).
        elements: Vec<u64>,
    },
}

/// A decoded geometry item: its record, `name` and the entity type as written.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometryItem<'a> {
    /// `name` of REPRESENTATION_ITEM (or REPRESENTATION), when present.
    pub name: Option<StepString<'a>>,
    /// The most specific entity type read (`CIRCLE`, `SEAM_CURVE`, `ADVANCED_FACE`...).
    pub entity: GeometryEntity,
    /// The entity type as written (`(BOUNDED_CURVE,...)` for a complex instance); for a
    /// simple instance the long name, [`GeometryItem::entity`] (no allocation per item).
    pub entity_type: Cow<'static, str>,
    /// The attributes.
    pub record: GeometryRecord<'a>,
}

/// The entity types this module reads, most specific first (a complex instance is read as
/// the first one it contains).
pub const GEOMETRY_ENTITIES: &[&str] = &[
    "DIRECTION",
    "VECTOR",
    "AXIS1_PLACEMENT",
    "AXIS2_PLACEMENT_2D",
    "AXIS2_PLACEMENT_3D",
    "LINE",
    "CIRCLE",
    "ELLIPSE",
    "HYPERBOLA",
    "PARABOLA",
    "POLYLINE",
    "TRIMMED_CURVE",
    "COMPOSITE_CURVE",
    "COMPOSITE_CURVE_SEGMENT",
    "SEAM_CURVE",
    "INTERSECTION_CURVE",
    "SURFACE_CURVE",
    "PCURVE",
    "DEFINITIONAL_REPRESENTATION",
    "PLANE",
    "CYLINDRICAL_SURFACE",
    "CONICAL_SURFACE",
    "SPHERICAL_SURFACE",
    "DEGENERATE_TOROIDAL_SURFACE",
    "TOROIDAL_SURFACE",
    "SURFACE_OF_LINEAR_EXTRUSION",
    "SURFACE_OF_REVOLUTION",
    "RECTANGULAR_TRIMMED_SURFACE",
    "OFFSET_CURVE_2D",
    "OFFSET_CURVE_3D",
    "OFFSET_SURFACE",
    "VERTEX_POINT",
    "EDGE_CURVE",
    "ORIENTED_EDGE",
    "EDGE_LOOP",
    "FACE_OUTER_BOUND",
    "FACE_BOUND",
    "ADVANCED_FACE",
    "FACE_SURFACE",
    "ORIENTED_FACE",
    "VERTEX_LOOP",
    "POLY_LOOP",
    "OPEN_SHELL",
    "ORIENTED_CLOSED_SHELL",
    "CLOSED_SHELL",
    "BREP_WITH_VOIDS",
    "MANIFOLD_SOLID_BREP",
    "SHELL_BASED_SURFACE_MODEL",
    "FACE_BASED_SURFACE_MODEL",
    "GEOMETRIC_CURVE_SET",
    "GEOMETRIC_SET",
];

/// The one entry of [`GEOMETRY_ENTITIES`] starting with `B`: kept out of the first-letter
/// mask (B-splines start with `B` too) and compared on its own.
const BREP_WITH_VOIDS: &str = "BREP_WITH_VOIDS";

/// Bit `c - 'A'` set for each first letter `c` of [`GEOMETRY_ENTITIES`] except
/// [`BREP_WITH_VOIDS`]'s.
const FIRST_LETTERS: u32 = {
    let mut mask = 0u32;
    let mut i = 0;
    while i < GEOMETRY_ENTITIES.len() {
        let first = GEOMETRY_ENTITIES[i].as_bytes()[0];
        if first != b'B' {
            mask |= 1 << (first - b'A');
        }
        i += 1;
    }
    mask
};

/// One of [`GEOMETRY_ENTITIES`], held as its position in the table (one byte: a reader
/// keeps one per decoded item, and a large B-rep has millions).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct GeometryEntity(u8);

impl GeometryEntity {
    /// The entry named `name` (a long-form name), if the table has it. The entries are
    /// grouped by length on first use, so a name is compared with the few of its length
    /// only (every geometry instance of a file is looked up here, and the table has over 40
    /// entries).
    pub fn named(name: &str) -> Option<Self> {
        type ByLength = Vec<Vec<(&'static str, GeometryEntity)>>;
        static BY_LENGTH: std::sync::OnceLock<ByLength> = std::sync::OnceLock::new();
        let table = BY_LENGTH.get_or_init(|| {
            let longest = GEOMETRY_ENTITIES.iter().map(|e| e.len()).max().unwrap_or(0);
            let mut table = vec![Vec::new(); longest + 1];
            for (k, &e) in GEOMETRY_ENTITIES.iter().enumerate() {
                if let (Some(group), Ok(k)) = (table.get_mut(e.len()), u8::try_from(k)) {
                    group.push((e, GeometryEntity(k)));
                }
            }
            table
        });
        // The first byte before the whole text: most names of one length differ there.
        let first = name.as_bytes().first();
        table
            .get(name.len())?
            .iter()
            .find(|(e, _)| e.as_bytes().first() == first && *e == name)
            .map(|&(_, g)| g)
    }

    /// [`GeometryEntity::named`] where a constant is needed ([`known_entity`]): a plain
    /// search of the table, evaluated by the compiler.
    pub(crate) const fn in_table(name: &str) -> Option<Self> {
        let name = name.as_bytes();
        // Below 256 entries (checked below): a byte counts them.
        let mut i: u8 = 0;
        while (i as usize) < GEOMETRY_ENTITIES.len() {
            let entry = GEOMETRY_ENTITIES[i as usize].as_bytes();
            if entry.len() == name.len() {
                let mut k = 0;
                while k < entry.len() && entry[k] == name[k] {
                    k += 1;
                }
                if k == entry.len() {
                    return Some(GeometryEntity(i));
                }
            }
            i += 1;
        }
        None
    }

    /// The entity's long name.
    pub fn name(self) -> &'static str {
        GEOMETRY_ENTITIES
            .get(usize::from(self.0))
            .copied()
            .unwrap_or_default()
    }
}

// One byte holds every position of the table, and counts past the last.
const _: () = assert!(GEOMETRY_ENTITIES.len() < 256);

/// `GeometryEntity::named(name)` in a constant (a compile error when the table lacks it).
macro_rules! known_entity {
    ($name:literal) => {
        const {
            match $crate::step::geometry::GeometryEntity::in_table($name) {
                Some(e) => e,
                None => panic!(concat!("not in GEOMETRY_ENTITIES: ", $name)),
            }
        }
    };
}
pub(crate) use known_entity;

impl PartialEq<&str> for GeometryEntity {
    fn eq(&self, other: &&str) -> bool {
        self.name() == *other
    }
}

impl std::fmt::Debug for GeometryEntity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(self.name(), f)
    }
}

impl std::fmt::Display for GeometryEntity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Whether the body of a complex instance may hold a partial record this module reads. The
/// complex instances that are rational B-splines (the B-spline decoder's; their
/// `B_SPLINE_` partial comes within the first few names), representation contexts or units
/// (most of a B-rep's: one per pcurve) hold none.
pub fn maybe_complex_geometry(body: &str) -> bool {
    use super::product::Needle;
    use memchr::memmem::Finder;
    static BSPLINE: Needle = Needle::new(|| Finder::new("B_SPLINE_"));
    static CONTEXT: Needle = Needle::new(|| Finder::new("REPRESENTATION_CONTEXT"));
    static UNIT: Needle = Needle::new(|| Finder::new("_UNIT"));
    ![&BSPLINE, &CONTEXT, &UNIT]
        .iter()
        .any(|n| n.find(body.as_bytes()).is_some())
}

/// Whether an entity name (long or short form) is one this module reads.
///
/// Every simple instance of a file passes here, most of them CARTESIAN_POINTs and
/// B-splines: the first letter (a mask built from the table, without `B`) and one
/// comparison turn those away before the table is searched.
pub fn is_geometry_entity(keyword: &str) -> bool {
    let k = canonical_name(keyword);
    let Some(&first) = k.as_bytes().first() else {
        return false;
    };
    let letter = first.wrapping_sub(b'A');
    if letter < 26 && FIRST_LETTERS & (1 << letter) != 0 {
        k != "CARTESIAN_POINT" && GeometryEntity::named(k).is_some()
    } else {
        first == b'B' && k == BREP_WITH_VOIDS
    }
}

fn trimming_selects(p: &Parameter<'_>) -> Result<Box<[TrimmingSelect]>, String> {
    let Some(list) = p.as_list() else {
        return Err(format!(
            "expected a list of trimming selects, found {}",
            render(p)
        ));
    };
    if list.is_empty() || list.len() > 2 {
        return Err(format!(
            "expected 1 or 2 trimming selects, found {}",
            list.len()
        ));
    }
    list.iter()
        .enumerate()
        .map(|(i, e)| match e {
            Parameter::Reference(id) => Ok(TrimmingSelect::Point(*id)),
            Parameter::Typed(k, v) if canonical_name(k) == "PARAMETER_VALUE" => v
                .as_real()
                .map(TrimmingSelect::Parameter)
                .ok_or_else(|| {
                    format!(
                        "element {}: PARAMETER_VALUE needs a real, found {}",
                        i + 1,
                        render(v)
                    )
                }),
            other => Err(format!(
                "element {}: expected a CARTESIAN_POINT reference or PARAMETER_VALUE(real), found {}",
                i + 1,
                render(other)
            )),
        })
        .collect()
}

impl<'a> GeometryItem<'a> {
    /// Reads an instance of one of [`GEOMETRY_ENTITIES`] (simple or complex); `Ok(None)`
    /// when it is none of them.
    pub fn from_instance(inst: &Instance<'a>, at: At) -> Result<Option<Self>, SchemaError> {
        // A simple instance is its keyword's entity; a complex one the most specific
        // geometry partial it holds.
        let simple = match &inst.body {
            Body::Simple(r) => {
                let name = canonical_name(r.keyword);
                match GeometryEntity::named(name) {
                    Some(e) => Some(e),
                    None => return Ok(None),
                }
            }
            Body::Complex(_) => None,
        };
        let a = Attributes::of(inst, at)?;
        let Some(kind) = simple.or_else(|| {
            GEOMETRY_ENTITIES
                .iter()
                .position(|e| a.has(e))
                .and_then(|k| u8::try_from(k).ok())
                .map(GeometryEntity)
        }) else {
            return Ok(None);
        };
        let entity = kind.name();
        use GeometryRecord as R;
        let record = match entity {
            "DIRECTION" => R::Direction {
                direction_ratios: {
                    let v = a.reals(entity, "direction_ratios")?;
                    a.checked(entity, "direction_ratios", |_| {
                        Ratios::new(&v).ok_or_else(|| {
                            format!("expected 2 or 3 direction ratios, found {}", v.len())
                        })
                    })?
                },
            },
            "VECTOR" => R::Vector {
                orientation: a.reference(entity, "orientation")?,
                magnitude: a.real(entity, "magnitude")?,
            },
            "AXIS1_PLACEMENT" => R::Axis1Placement {
                location: a.reference("PLACEMENT", "location")?,
                axis: a.optional_reference(entity, "axis")?,
            },
            "AXIS2_PLACEMENT_2D" => R::Axis2Placement2d {
                location: a.reference("PLACEMENT", "location")?,
                ref_direction: a.optional_reference(entity, "ref_direction")?,
            },
            "AXIS2_PLACEMENT_3D" => R::Axis2Placement3d {
                location: a.reference("PLACEMENT", "location")?,
                axis: a.optional_reference(entity, "axis")?,
                ref_direction: a.optional_reference(entity, "ref_direction")?,
            },
            "LINE" => R::Line {
                pnt: a.reference(entity, "pnt")?,
                dir: a.reference(entity, "dir")?,
            },
            "CIRCLE" => R::Circle {
                position: a.reference("CONIC", "position")?,
                radius: a.real(entity, "radius")?,
            },
            "ELLIPSE" => R::Ellipse {
                position: a.reference("CONIC", "position")?,
                semi_axis_1: a.real(entity, "semi_axis_1")?,
                semi_axis_2: a.real(entity, "semi_axis_2")?,
            },
            "HYPERBOLA" => R::Hyperbola {
                position: a.reference("CONIC", "position")?,
                semi_axis: a.real(entity, "semi_axis")?,
                semi_imag_axis: a.real(entity, "semi_imag_axis")?,
            },
            "PARABOLA" => R::Parabola {
                position: a.reference("CONIC", "position")?,
                focal_dist: a.real(entity, "focal_dist")?,
            },
            "POLYLINE" => R::Polyline {
                points: a.references(entity, "points")?,
            },
            "TRIMMED_CURVE" => R::TrimmedCurve {
                basis_curve: a.reference(entity, "basis_curve")?,
                trimming: Box::new(Trimming {
                    trim_1: a.checked(entity, "trim_1", trimming_selects)?,
                    trim_2: a.checked(entity, "trim_2", trimming_selects)?,
                    sense_agreement: a.boolean(entity, "sense_agreement")?,
                    master_representation: a.enumeration(entity, "master_representation")?,
                }),
            },
            "COMPOSITE_CURVE" => R::CompositeCurve {
                segments: a.references(entity, "segments")?,
                self_intersect: a.logical(entity, "self_intersect")?,
            },
            "COMPOSITE_CURVE_SEGMENT" => R::CompositeCurveSegment {
                transition: a.enumeration(entity, "transition")?,
                same_sense: a.boolean(entity, "same_sense")?,
                parent_curve: a.reference(entity, "parent_curve")?,
            },
            "SEAM_CURVE" | "INTERSECTION_CURVE" | "SURFACE_CURVE" => R::SurfaceCurve {
                curve_3d: a.reference("SURFACE_CURVE", "curve_3d")?,
                associated_geometry: a
                    .references("SURFACE_CURVE", "associated_geometry")?
                    .into_boxed_slice(),
                master_representation: a.enumeration("SURFACE_CURVE", "master_representation")?,
            },
            "PCURVE" => R::Pcurve {
                basis_surface: a.reference(entity, "basis_surface")?,
                reference_to_curve: a.reference(entity, "reference_to_curve")?,
            },
            "DEFINITIONAL_REPRESENTATION" => R::DefinitionalRepresentation {
                items: Refs::from_vec(a.references("REPRESENTATION", "items")?),
                context_of_items: a.reference("REPRESENTATION", "context_of_items")?,
            },
            "PLANE" => R::Plane {
                position: a.reference("ELEMENTARY_SURFACE", "position")?,
            },
            "CYLINDRICAL_SURFACE" => R::CylindricalSurface {
                position: a.reference("ELEMENTARY_SURFACE", "position")?,
                radius: a.real(entity, "radius")?,
            },
            "CONICAL_SURFACE" => R::ConicalSurface {
                position: a.reference("ELEMENTARY_SURFACE", "position")?,
                radius: a.real(entity, "radius")?,
                semi_angle: a.real(entity, "semi_angle")?,
            },
            "SPHERICAL_SURFACE" => R::SphericalSurface {
                position: a.reference("ELEMENTARY_SURFACE", "position")?,
                radius: a.real(entity, "radius")?,
            },
            "DEGENERATE_TOROIDAL_SURFACE" | "TOROIDAL_SURFACE" => R::ToroidalSurface {
                position: a.reference("ELEMENTARY_SURFACE", "position")?,
                major_radius: a.real("TOROIDAL_SURFACE", "major_radius")?,
                minor_radius: a.real("TOROIDAL_SURFACE", "minor_radius")?,
                select_outer: if entity == "DEGENERATE_TOROIDAL_SURFACE" {
                    Some(a.boolean(entity, "select_outer")?)
                } else {
                    None
                },
            },
            "SURFACE_OF_LINEAR_EXTRUSION" => R::SurfaceOfLinearExtrusion {
                swept_curve: a.reference("SWEPT_SURFACE", "swept_curve")?,
                extrusion_axis: a.reference(entity, "extrusion_axis")?,
            },
            "SURFACE_OF_REVOLUTION" => R::SurfaceOfRevolution {
                swept_curve: a.reference("SWEPT_SURFACE", "swept_curve")?,
                axis_position: a.reference(entity, "axis_position")?,
            },
            "RECTANGULAR_TRIMMED_SURFACE" => R::RectangularTrimmedSurface {
                basis_surface: a.reference(entity, "basis_surface")?,
                bounds: Box::new(RectangularTrim {
                    u1: a.real(entity, "u1")?,
                    u2: a.real(entity, "u2")?,
                    v1: a.real(entity, "v1")?,
                    v2: a.real(entity, "v2")?,
                    usense: a.boolean(entity, "usense")?,
                    vsense: a.boolean(entity, "vsense")?,
                }),
            },
            "OFFSET_CURVE_2D" | "OFFSET_CURVE_3D" => R::Offset {
                basis: a.reference(entity, "basis_curve")?,
            },
            "OFFSET_SURFACE" => R::Offset {
                basis: a.reference(entity, "basis_surface")?,
            },
            "VERTEX_POINT" => R::VertexPoint {
                vertex_geometry: a.reference(entity, "vertex_geometry")?,
            },
            "EDGE_CURVE" => R::EdgeCurve {
                edge_start: a.reference("EDGE", "edge_start")?,
                edge_end: a.reference("EDGE", "edge_end")?,
                edge_geometry: a.reference(entity, "edge_geometry")?,
                same_sense: a.boolean(entity, "same_sense")?,
            },
            "ORIENTED_EDGE" => R::OrientedEdge {
                edge_element: a.reference(entity, "edge_element")?,
                orientation: a.boolean(entity, "orientation")?,
            },
            "EDGE_LOOP" => R::EdgeLoop {
                edge_list: a.references("PATH", "edge_list")?,
            },
            "FACE_OUTER_BOUND" | "FACE_BOUND" => R::FaceBound {
                bound: a.reference("FACE_BOUND", "bound")?,
                orientation: a.boolean("FACE_BOUND", "orientation")?,
            },
            "VERTEX_LOOP" => R::VertexLoop {
                loop_vertex: a.reference(entity, "loop_vertex")?,
            },
            "POLY_LOOP" => R::PolyLoop {
                polygon: a.references(entity, "polygon")?,
            },
            "OPEN_SHELL" | "CLOSED_SHELL" => R::Shell {
                cfs_faces: a.references("CONNECTED_FACE_SET", "cfs_faces")?,
                closed: entity == "CLOSED_SHELL",
            },
            "ORIENTED_FACE" => R::OrientedFace {
                face_element: a.reference(entity, "face_element")?,
                orientation: a.boolean(entity, "orientation")?,
            },
            "ORIENTED_CLOSED_SHELL" => R::OrientedClosedShell {
                closed_shell_element: a.reference(entity, "closed_shell_element")?,
                orientation: a.boolean(entity, "orientation")?,
            },
            "BREP_WITH_VOIDS" | "MANIFOLD_SOLID_BREP" => R::ManifoldSolidBrep {
                outer: a.reference("MANIFOLD_SOLID_BREP", "outer")?,
                voids: if entity == "BREP_WITH_VOIDS" {
                    a.references(entity, "voids")?
                } else {
                    Vec::new()
                },
            },
            "SHELL_BASED_SURFACE_MODEL" => R::ShellBasedSurfaceModel {
                sbsm_boundary: a.references(entity, "sbsm_boundary")?,
            },
            "FACE_BASED_SURFACE_MODEL" => R::FaceBasedSurfaceModel {
                fbsm_faces: a.references(entity, "fbsm_faces")?,
            },
            "GEOMETRIC_CURVE_SET" | "GEOMETRIC_SET" => R::GeometricSet {
                elements: a.references("GEOMETRIC_SET", "elements")?,
            },
            _ => R::FaceSurface {
                bounds: Refs::from_vec(a.references("FACE", "bounds")?),
                face_geometry: a.reference("FACE_SURFACE", "face_geometry")?,
                same_sense: a.boolean("FACE_SURFACE", "same_sense")?,
            },
        };
        let name = a
            .string("REPRESENTATION_ITEM", "name")
            .or_else(|_| a.string("REPRESENTATION", "name"))
            .ok();
        Ok(Some(GeometryItem {
            name,
            entity: kind,
            entity_type: match simple {
                Some(e) => Cow::Borrowed(e.name()),
                None => Cow::Owned(a.entity_type().to_owned()),
            },
            record,
        }))
    }
}

impl<'a> Scanned<'a> {
    /// The entity type as written and the name of a geometry instance decoded before
    /// ([`Scanned::geometry_item`] gave it): read from the instance's start alone when it
    /// is in the usual form, else decoded again.
    #[allow(clippy::type_complexity)]
    pub fn geometry_provenance(
        &self,
        raw: &RawInstance<'a>,
    ) -> Result<Option<(Cow<'static, str>, Option<StepString<'a>>)>, DecodeError> {
        if let Some((entity, name)) =
            super::geometry_text::name(self.text, raw, self.param_limits())
        {
            return Ok(Some((Cow::Borrowed(entity), Some(name))));
        }
        self.geometry_item(raw)
            .map(|item| item.map(|i| (i.entity_type, i.name)))
    }

    /// Decodes instance `raw` as one of [`GEOMETRY_ENTITIES`]; `Ok(None)` when it is
    /// another entity. The usual simple instances of a B-rep (placements, lines, circles,
    /// elementary surfaces, surface curves and pcurves, vertices, edges, loops, faces,
    /// shells) are read from their text in one pass (private to this decoder); any other
    /// shape through the grammar, by attribute name, with the same item or the located
    /// error.
    #[inline]
    pub fn geometry_item(
        &self,
        raw: &RawInstance<'a>,
    ) -> Result<Option<GeometryItem<'a>>, DecodeError> {
        if let Some(item) = super::geometry_text::read(self.text, raw, self.param_limits()) {
            return Ok(Some(item));
        }
        let inst = self.decode(raw)?;
        // The line and column are looked up only for an error (finding them counts the
        // lines before the instance, a visible cost when every instance is decoded).
        let at = At {
            id: raw.id,
            line: 0,
            column: 0,
        };
        GeometryItem::from_instance(&inst, at).map_err(|e| {
            let (line, column) = self.locate(raw.offset());
            DecodeError::Schema(SchemaError { line, column, ..e })
        })
    }
}

#[cfg(test)]
#[path = "geometry_tests.rs"]
mod tests;
