//! Length units: the IGES 5.3 Global-section unit flags (section 2.2.4.3, parameter 14) and
//! the STEP SI / conversion-based units, with their factors to millimetres.

use serde::Serialize;

/// A length unit with an exact factor to millimetres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Millimetre (IGES flag 2).
    Mm,
    /// Centimetre (IGES flag 10).
    Cm,
    /// Metre (IGES flag 6).
    M,
    /// Kilometre (IGES flag 7).
    Km,
    /// Micrometre (IGES flag 9).
    Um,
    /// Inch, 25.4 mm (IGES flag 1).
    In,
    /// Foot, 304.8 mm (IGES flag 4).
    Ft,
    /// Statute mile, 1609344 mm (IGES flag 5).
    Mi,
    /// Mil, 0.0254 mm (IGES flag 8).
    Mil,
    /// Microinch, 0.0000254 mm (IGES flag 11).
    Uin,
}

impl LengthUnit {
    /// Millimetres per unit.
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::Cm => 10.0,
            LengthUnit::M => 1000.0,
            LengthUnit::Km => 1e6,
            LengthUnit::Um => 1e-3,
            LengthUnit::In => 25.4,
            LengthUnit::Ft => 304.8,
            LengthUnit::Mi => 1_609_344.0,
            LengthUnit::Mil => 0.0254,
            LengthUnit::Uin => 0.0000254,
        }
    }

    /// The IGES 5.3 units flag (Global parameter 14).
    pub fn iges_flag(self) -> i64 {
        match self {
            LengthUnit::In => 1,
            LengthUnit::Mm => 2,
            LengthUnit::Ft => 4,
            LengthUnit::Mi => 5,
            LengthUnit::M => 6,
            LengthUnit::Km => 7,
            LengthUnit::Mil => 8,
            LengthUnit::Um => 9,
            LengthUnit::Cm => 10,
            LengthUnit::Uin => 11,
        }
    }

    /// The unit for an IGES units flag (3 = "named in parameter 15" has no unit by itself).
    pub fn from_iges_flag(flag: i64) -> Option<Self> {
        Some(match flag {
            1 => LengthUnit::In,
            2 => LengthUnit::Mm,
            4 => LengthUnit::Ft,
            5 => LengthUnit::Mi,
            6 => LengthUnit::M,
            7 => LengthUnit::Km,
            8 => LengthUnit::Mil,
            9 => LengthUnit::Um,
            10 => LengthUnit::Cm,
            11 => LengthUnit::Uin,
            _ => return None,
        })
    }

    /// The IGES units name (Global parameter 15) as IGES 5.3 spells it.
    pub fn iges_name(self) -> &'static str {
        match self {
            LengthUnit::In => "INCH",
            LengthUnit::Mm => "MM",
            LengthUnit::Ft => "FT",
            LengthUnit::Mi => "MI",
            LengthUnit::M => "M",
            LengthUnit::Km => "KM",
            LengthUnit::Mil => "MIL",
            LengthUnit::Um => "UM",
            LengthUnit::Cm => "CM",
            LengthUnit::Uin => "UIN",
        }
    }

    /// Parses a unit name as used by IGES parameter 15, the CLI (`mm`, `in`...) and STEP
    /// conversion-based unit names (`INCH`, `FOOT`); case-insensitive.
    pub fn parse_name(name: &str) -> Option<Self> {
        Some(match name.trim().to_ascii_uppercase().as_str() {
            "MM" | "MILLIMETRE" | "MILLIMETER" => LengthUnit::Mm,
            "CM" | "CENTIMETRE" | "CENTIMETER" => LengthUnit::Cm,
            "M" | "METRE" | "METER" => LengthUnit::M,
            "KM" | "KILOMETRE" | "KILOMETER" => LengthUnit::Km,
            "UM" | "MICRON" | "MICROMETRE" | "MICROMETER" => LengthUnit::Um,
            "IN" | "INCH" | "INCHES" => LengthUnit::In,
            "FT" | "FOOT" | "FEET" => LengthUnit::Ft,
            "MI" | "MILE" => LengthUnit::Mi,
            "MIL" | "MILS" => LengthUnit::Mil,
            "UIN" | "MICROINCH" => LengthUnit::Uin,
            _ => return None,
        })
    }

    /// Short lower-case name (`mm`, `in`...), as the CLI and JSON use.
    pub fn short_name(self) -> &'static str {
        match self {
            LengthUnit::Mm => "mm",
            LengthUnit::Cm => "cm",
            LengthUnit::M => "m",
            LengthUnit::Km => "km",
            LengthUnit::Um => "um",
            LengthUnit::In => "in",
            LengthUnit::Ft => "ft",
            LengthUnit::Mi => "mi",
            LengthUnit::Mil => "mil",
            LengthUnit::Uin => "uin",
        }
    }
}
