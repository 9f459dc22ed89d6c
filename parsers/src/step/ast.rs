//! The Part 21 syntax tree. Everything borrows from the input text: keywords, enumeration
//! values, binary literals and raw strings are slices of it; nothing is allocated per token
//! except the parameter vectors.

use super::StepString;

/// One parameter (ISO 10303-21 clause 12.2.2, `parameter = typed_parameter |
/// untyped_parameter | omitted_parameter`).
#[derive(Debug, Clone, PartialEq)]
pub enum Parameter<'a> {
    /// `INTEGER`.
    Integer(i64),
    /// `REAL` (always written with a decimal point).
    Real(f64),
    /// `STRING`, raw (decode with [`StepString::decode`]).
    String(StepString<'a>),
    /// `ENUMERATION`: the value without its dots (`T`, `UNSPECIFIED`).
    Enumeration(&'a str),
    /// `BINARY`: the hex digits between the quotes (first digit = unused bits).
    Binary(&'a str),
    /// An entity instance name `#n`.
    Reference(u64),
    /// `$`: not provided.
    Null,
    /// `*`: derived (redeclared in a subtype).
    Derived,
    /// `KEYWORD(parameter)`: a value of a defined type, e.g. `LENGTH_MEASURE(1.E-07)`.
    Typed(&'a str, Box<Parameter<'a>>),
    /// `( ... )`, possibly empty, possibly nested.
    List(Vec<Parameter<'a>>),
}

impl<'a> Parameter<'a> {
    /// The integer, if this is one.
    pub fn as_integer(&self) -> Option<i64> {
        match self {
            Parameter::Integer(i) => Some(*i),
            _ => None,
        }
    }

    /// A REAL, or an INTEGER widened (Part 21 writers emit `0` for a real zero; Open
    /// CASCADE accepts it as a real).
    pub fn as_real(&self) -> Option<f64> {
        match self {
            Parameter::Real(r) => Some(*r),
            // i64 -> f64 may round above 2^53; such integers are not real-world coordinates.
            Parameter::Integer(i) => Some(*i as f64),
            _ => None,
        }
    }

    /// The referenced id, if this is a reference.
    pub fn as_reference(&self) -> Option<u64> {
        match self {
            Parameter::Reference(r) => Some(*r),
            _ => None,
        }
    }

    /// The enumeration value (without dots), if this is one.
    pub fn as_enumeration(&self) -> Option<&'a str> {
        match self {
            Parameter::Enumeration(e) => Some(e),
            _ => None,
        }
    }

    /// The string, if this is one.
    pub fn as_string(&self) -> Option<&StepString<'a>> {
        match self {
            Parameter::String(s) => Some(s),
            _ => None,
        }
    }

    /// The elements, if this is a list.
    pub fn as_list(&self) -> Option<&[Parameter<'a>]> {
        match self {
            Parameter::List(l) => Some(l),
            _ => None,
        }
    }

    /// A short description of the parameter's kind, for "expected X, found Y" messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Parameter::Integer(_) => "an integer",
            Parameter::Real(_) => "a real",
            Parameter::String(_) => "a string",
            Parameter::Enumeration(_) => "an enumeration",
            Parameter::Binary(_) => "a binary",
            Parameter::Reference(_) => "a reference",
            Parameter::Null => "`$`",
            Parameter::Derived => "`*`",
            Parameter::Typed(..) => "a typed parameter",
            Parameter::List(_) => "a list",
        }
    }
}

/// A keyword with its parameter list: a simple record, a partial entity of a complex
/// instance, or a header entity.
#[derive(Debug, Clone, PartialEq)]
pub struct Record<'a> {
    /// Entity name as written (upper case; `!` prefix for user-defined keywords).
    pub keyword: &'a str,
    /// The parameters in order.
    pub params: Vec<Parameter<'a>>,
}

/// The right-hand side of an entity instance.
#[derive(Debug, Clone, PartialEq)]
pub enum Body<'a> {
    /// `#n = KEYWORD(...)`.
    Simple(Record<'a>),
    /// `#n = (A(...) B(...) ...)`: the external mapping of a complex entity (ISO 10303-21
    /// clause 12.2.5), one partial record per entity data type, each holding only the
    /// attributes that entity itself declares.
    Complex(Vec<Record<'a>>),
}

impl<'a> Body<'a> {
    /// The records: one for a simple instance, the partials of a complex one.
    pub fn records(&self) -> &[Record<'a>] {
        match self {
            Body::Simple(r) => std::slice::from_ref(r),
            Body::Complex(rs) => rs,
        }
    }

    /// The partial record with this keyword (complex) or the record itself if its keyword
    /// matches (simple).
    pub fn record(&self, keyword: &str) -> Option<&Record<'a>> {
        self.records().iter().find(|r| r.keyword == keyword)
    }
}

/// An entity instance `#id = body;`.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance<'a> {
    /// The instance name `n` of `#n`.
    pub id: u64,
    /// Its record(s).
    pub body: Body<'a>,
}

/// One `DATA;` section (edition 3 allows several, each optionally with a name and schema
/// parameters: `DATA('name',('SCHEMA'));`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DataSection<'a> {
    /// The section's parameters (empty for the usual `DATA;`).
    pub params: Vec<Parameter<'a>>,
    /// The instances in file order.
    pub instances: Vec<Instance<'a>>,
}

/// A whole exchange structure.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Exchange<'a> {
    /// The header entities in order (`FILE_DESCRIPTION`, `FILE_NAME`, `FILE_SCHEMA`, and any
    /// others).
    pub header: Vec<Record<'a>>,
    /// The data sections.
    pub data: Vec<DataSection<'a>>,
}

impl<'a> Exchange<'a> {
    /// The header record with this keyword.
    pub fn header_record(&self, keyword: &str) -> Option<&Record<'a>> {
        self.header.iter().find(|r| r.keyword == keyword)
    }

    /// The schema identifiers of `FILE_SCHEMA(('A','B'))`, raw.
    pub fn schemas(&self) -> Vec<StepString<'a>> {
        schema_names(&self.header)
    }

    /// All instances of all sections, in file order.
    pub fn instances(&self) -> impl Iterator<Item = &Instance<'a>> {
        self.data.iter().flat_map(|d| d.instances.iter())
    }
}

/// The schema identifiers listed by `FILE_SCHEMA` in a header.
pub fn schema_names<'a>(header: &[Record<'a>]) -> Vec<StepString<'a>> {
    header
        .iter()
        .find(|r| r.keyword == "FILE_SCHEMA")
        .and_then(|r| r.params.first())
        .and_then(Parameter::as_list)
        .map(|l| l.iter().filter_map(Parameter::as_string).cloned().collect())
        .unwrap_or_default()
}
