//! Typed records of the product and representation structure that places parts in an
//! assembly: ISO 10303-41 product / product_definition_formation / product_definition /
//! product_definition_shape / shape_definition_representation and
//! next_assembly_usage_occurrence, ISO 10303-43 shape_representation (and its subtypes),
//! representation_relationship (with transformation), item_defined_transformation,
//! mapped_item and representation_map, and AP214's
//! context_dependent_shape_representation.
//!
//! Attributes are read by name from the tables of [`super::schema`], as
//! [`super::geometry`] reads its records, so simple and complex instances read the same.

use super::ast::{Body, Instance};
use super::error::SchemaError;
use super::scan::{RawInstance, Scanned};
use super::schema::{At, Attributes, DecodeError, canonical_name};
use super::string::StepString;
use memchr::memmem::Finder;

/// One entity of the product structure; each variant carries the explicit attributes the
/// assembly needs under their EXPRESS names.
#[derive(Debug, Clone, PartialEq)]
pub enum ProductRecord<'a> {
    /// `product` (ISO 10303-41): `id`, `name`.
    Product {
        /// `id`.
        id: Option<StepString<'a>>,
        /// `name`.
        name: Option<StepString<'a>>,
    },
    /// `product_definition_formation` (and `..._with_specified_source`): `of_product`.
    Formation {
        /// `of_product` (a PRODUCT).
        of_product: u64,
    },
    /// `product_definition` (and `..._with_associated_documents`): `formation`.
    Definition {
        /// `formation` (a PRODUCT_DEFINITION_FORMATION).
        formation: u64,
    },
    /// `product_definition_shape` (a property_definition): `definition` (a
    /// PRODUCT_DEFINITION, or a NEXT_ASSEMBLY_USAGE_OCCURRENCE for an instance's shape).
    DefinitionShape {
        /// `definition`.
        definition: u64,
    },
    /// `shape_definition_representation`: `definition` (a PRODUCT_DEFINITION_SHAPE),
    /// `used_representation` (a SHAPE_REPRESENTATION).
    ShapeDefinitionRepresentation {
        /// `definition`.
        definition: u64,
        /// `used_representation`.
        used_representation: u64,
    },
    /// `next_assembly_usage_occurrence` (ISO 10303-44): one use of a product definition in
    /// another.
    Usage {
        /// `id`.
        id: Option<StepString<'a>>,
        /// `name`.
        name: Option<StepString<'a>>,
        /// `relating_product_definition`: the assembly.
        relating: u64,
        /// `related_product_definition`: the component.
        related: u64,
    },
    /// `context_dependent_shape_representation` (AP214): the placement of one usage.
    ContextDependentShapeRepresentation {
        /// `representation_relation` (a SHAPE_REPRESENTATION_RELATIONSHIP, usually with
        /// transformation).
        representation_relation: u64,
        /// `represented_product_relation` (a PRODUCT_DEFINITION_SHAPE of the usage).
        represented_product_relation: u64,
    },
    /// `representation_relationship`, `shape_representation_relationship` and
    /// `representation_relationship_with_transformation` (ISO 10303-43).
    RepresentationRelationship {
        /// `rep_1`.
        rep_1: u64,
        /// `rep_2`.
        rep_2: u64,
        /// `transformation_operator` when the instance is a
        /// representation_relationship_with_transformation.
        transformation_operator: Option<u64>,
    },
    /// `item_defined_transformation` (ISO 10303-43): the map taking the placement
    /// `transform_item_1` onto `transform_item_2`.
    ItemDefinedTransformation {
        /// `transform_item_1`.
        transform_item_1: u64,
        /// `transform_item_2`.
        transform_item_2: u64,
    },
    /// `shape_representation` and its subtypes (ISO 10303-43 representation): `items`.
    ShapeRepresentation {
        /// `name`.
        name: Option<StepString<'a>>,
        /// `items`.
        items: Vec<u64>,
    },
    /// `mapped_item` (ISO 10303-43): `mapping_source` (a REPRESENTATION_MAP),
    /// `mapping_target` (the placement the map's origin goes to).
    MappedItem {
        /// `mapping_source`.
        mapping_source: u64,
        /// `mapping_target`.
        mapping_target: u64,
    },
    /// `representation_map` (ISO 10303-43): `mapping_origin`, `mapped_representation`.
    RepresentationMap {
        /// `mapping_origin`.
        mapping_origin: u64,
        /// `mapped_representation`.
        mapped_representation: u64,
    },
}

/// The entity types this module reads, most specific first (a complex instance is read as
/// the first one it contains).
pub const PRODUCT_ENTITIES: &[&str] = &[
    "PRODUCT",
    "PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE",
    "PRODUCT_DEFINITION_FORMATION",
    "PRODUCT_DEFINITION_WITH_ASSOCIATED_DOCUMENTS",
    "PRODUCT_DEFINITION",
    "PRODUCT_DEFINITION_SHAPE",
    "SHAPE_DEFINITION_REPRESENTATION",
    "NEXT_ASSEMBLY_USAGE_OCCURRENCE",
    "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION",
    "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
    "SHAPE_REPRESENTATION_RELATIONSHIP",
    "REPRESENTATION_RELATIONSHIP",
    "ITEM_DEFINED_TRANSFORMATION",
    "ADVANCED_BREP_SHAPE_REPRESENTATION",
    "FACETED_BREP_SHAPE_REPRESENTATION",
    "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
    "GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION",
    "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION",
    "EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION",
    "SHAPE_REPRESENTATION",
    "MAPPED_ITEM",
    "REPRESENTATION_MAP",
];

/// Whether a simple instance's keyword (long or short form) is one of
/// [`PRODUCT_ENTITIES`]. Most instances of a file are points and topology: the first
/// letter turns most of them away before the table is searched.
pub fn is_product_entity(keyword: &str) -> bool {
    let k = canonical_name(keyword);
    matches!(
        k.as_bytes().first(),
        Some(b'P' | b'S' | b'N' | b'C' | b'R' | b'I' | b'A' | b'F' | b'M' | b'G' | b'E')
    ) && k != "CARTESIAN_POINT"
        && PRODUCT_ENTITIES.contains(&k)
}

/// Whether a complex instance's body may hold one of [`PRODUCT_ENTITIES`] (the
/// representation relationships Open CASCADE writes as complex instances).
pub fn maybe_complex_product(body: &str) -> bool {
    static RELATIONSHIP: Needle = Needle::new(|| Finder::new("REPRESENTATION_RELATIONSHIP"));
    static SHAPE: Needle = Needle::new(|| Finder::new("SHAPE_REPRESENTATION"));
    [&RELATIONSHIP, &SHAPE]
        .iter()
        .any(|n| n.find(body.as_bytes()).is_some())
}

/// A substring searcher built once (a file has thousands of complex instances to test).
pub type Needle = std::sync::LazyLock<Finder<'static>>;

/// A decoded product-structure instance: its record and the entity type read.
#[derive(Debug, Clone, PartialEq)]
pub struct ProductItem<'a> {
    /// The most specific entity type read.
    pub entity: &'static str,
    /// The attributes.
    pub record: ProductRecord<'a>,
}

impl<'a> ProductItem<'a> {
    /// Reads an instance of one of [`PRODUCT_ENTITIES`] (simple or complex); `Ok(None)`
    /// when it is none of them.
    pub fn from_instance(inst: &Instance<'a>, at: At) -> Result<Option<Self>, SchemaError> {
        let simple = match &inst.body {
            Body::Simple(r) => {
                let name = canonical_name(r.keyword);
                match PRODUCT_ENTITIES.iter().find(|e| **e == name) {
                    Some(e) => Some(*e),
                    None => return Ok(None),
                }
            }
            Body::Complex(_) => None,
        };
        let a = Attributes::of(inst, at)?;
        let Some(entity) = simple.or_else(|| PRODUCT_ENTITIES.iter().copied().find(|e| a.has(e)))
        else {
            return Ok(None);
        };
        use ProductRecord as P;
        let record = match entity {
            "PRODUCT" => P::Product {
                id: a.string(entity, "id").ok(),
                name: a.string(entity, "name").ok(),
            },
            "PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE"
            | "PRODUCT_DEFINITION_FORMATION" => P::Formation {
                of_product: a.reference("PRODUCT_DEFINITION_FORMATION", "of_product")?,
            },
            "PRODUCT_DEFINITION_WITH_ASSOCIATED_DOCUMENTS" | "PRODUCT_DEFINITION" => {
                P::Definition {
                    formation: a.reference("PRODUCT_DEFINITION", "formation")?,
                }
            }
            "PRODUCT_DEFINITION_SHAPE" => P::DefinitionShape {
                definition: a.reference("PROPERTY_DEFINITION", "definition")?,
            },
            "SHAPE_DEFINITION_REPRESENTATION" => P::ShapeDefinitionRepresentation {
                definition: a.reference("PROPERTY_DEFINITION_REPRESENTATION", "definition")?,
                used_representation: a
                    .reference("PROPERTY_DEFINITION_REPRESENTATION", "used_representation")?,
            },
            "NEXT_ASSEMBLY_USAGE_OCCURRENCE" => P::Usage {
                id: a.string("PRODUCT_DEFINITION_RELATIONSHIP", "id").ok(),
                name: a.string("PRODUCT_DEFINITION_RELATIONSHIP", "name").ok(),
                relating: a.reference(
                    "PRODUCT_DEFINITION_RELATIONSHIP",
                    "relating_product_definition",
                )?,
                related: a.reference(
                    "PRODUCT_DEFINITION_RELATIONSHIP",
                    "related_product_definition",
                )?,
            },
            "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION" => P::ContextDependentShapeRepresentation {
                representation_relation: a.reference(entity, "representation_relation")?,
                represented_product_relation: a
                    .reference(entity, "represented_product_relation")?,
            },
            "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION"
            | "SHAPE_REPRESENTATION_RELATIONSHIP"
            | "REPRESENTATION_RELATIONSHIP" => P::RepresentationRelationship {
                rep_1: a.reference("REPRESENTATION_RELATIONSHIP", "rep_1")?,
                rep_2: a.reference("REPRESENTATION_RELATIONSHIP", "rep_2")?,
                transformation_operator: if a.has("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION")
                {
                    Some(a.reference(
                        "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
                        "transformation_operator",
                    )?)
                } else {
                    None
                },
            },
            "ITEM_DEFINED_TRANSFORMATION" => P::ItemDefinedTransformation {
                transform_item_1: a.reference(entity, "transform_item_1")?,
                transform_item_2: a.reference(entity, "transform_item_2")?,
            },
            "MAPPED_ITEM" => P::MappedItem {
                mapping_source: a.reference(entity, "mapping_source")?,
                mapping_target: a.reference(entity, "mapping_target")?,
            },
            "REPRESENTATION_MAP" => P::RepresentationMap {
                mapping_origin: a.reference(entity, "mapping_origin")?,
                mapped_representation: a.reference(entity, "mapped_representation")?,
            },
            // The shape representations.
            _ => P::ShapeRepresentation {
                name: a.string("REPRESENTATION", "name").ok(),
                items: a.references("REPRESENTATION", "items")?,
            },
        };
        Ok(Some(ProductItem { entity, record }))
    }
}

impl<'a> Scanned<'a> {
    /// Decodes instance `raw` as one of [`PRODUCT_ENTITIES`]; `Ok(None)` when it is another
    /// entity.
    pub fn product_item(
        &self,
        raw: &RawInstance<'a>,
    ) -> Result<Option<ProductItem<'a>>, DecodeError> {
        let inst = self.decode(raw)?;
        let (line, column) = self.locate(raw.offset());
        let at = At {
            id: raw.id,
            line,
            column,
        };
        Ok(ProductItem::from_instance(&inst, at)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Limits;
    use crate::step::scan;

    fn file(data: &str) -> String {
        format!("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n")
    }

    fn decode(text: &str) -> String {
        let data = file(text);
        let s = scan(&data, &Limits::default()).unwrap();
        let raw = s.get(1).unwrap();
        format!("{:?}", s.product_item(raw).unwrap().unwrap().record)
    }

    #[test]
    fn reads_the_usage_and_its_placement() {
        assert_eq!(
            decode("#1=NEXT_ASSEMBLY_USAGE_OCCURRENCE('2','Bracket_2','',#5,#35,$);"),
            format!(
                "{:?}",
                ProductRecord::Usage {
                    id: Some(StepString::new("2")),
                    name: Some(StepString::new("Bracket_2")),
                    relating: 5,
                    related: 35
                }
            )
        );
        let relation = |t| {
            format!(
                "{:?}",
                ProductRecord::RepresentationRelationship {
                    rep_1: 40,
                    rep_2: 10,
                    transformation_operator: t
                }
            )
        };
        assert_eq!(
            decode(
                "#1=( REPRESENTATION_RELATIONSHIP('','',#40,#10) \
                 REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#462) \
                 SHAPE_REPRESENTATION_RELATIONSHIP() );"
            ),
            relation(Some(462))
        );
        assert_eq!(
            decode("#1=SHAPE_REPRESENTATION_RELATIONSHIP('','',#40,#10);"),
            relation(None)
        );
        assert!(
            decode("#1=ADVANCED_BREP_SHAPE_REPRESENTATION('',(#11,#41),#455);")
                .contains("items: [11, 41]")
        );
        assert!(is_product_entity("MAPPED_ITEM"));
        assert!(!is_product_entity("CARTESIAN_POINT"));
        assert!(!is_product_entity("EDGE_CURVE"));
    }

    #[test]
    fn wrong_attribute_count_is_a_schema_error() {
        let data = file("#1=ITEM_DEFINED_TRANSFORMATION('','',#2);");
        let s = scan(&data, &Limits::default()).unwrap();
        let raw = s.get(1).unwrap();
        assert!(s.product_item(raw).is_err());
    }
}
