//! The Global section: delimiters and the 26 typed parameters (IGES 5.3 section
//! 2.2.4.3). The rule that reads it is [`super::grammar::global`].

use super::grammar::parameters::Delimiters;

/// The Global section, every parameter typed. Empty (defaulted) parameters are `None`,
/// except the delimiters, which always hold the effective value.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Global {
    /// 1: parameter delimiter (default `,`).
    pub param_delimiter: char,
    /// 2: record delimiter (default `;`).
    pub record_delimiter: char,
    /// 3: product identification from the sending system.
    pub product_id_sender: Option<String>,
    /// 4: file name.
    pub file_name: Option<String>,
    /// 5: native system id.
    pub native_system_id: Option<String>,
    /// 6: preprocessor version.
    pub preprocessor_version: Option<String>,
    /// 7: number of binary bits for integer representation.
    pub integer_bits: Option<i64>,
    /// 8: maximum power of ten representable in single precision.
    pub single_max_power: Option<i64>,
    /// 9: significant digits in single precision.
    pub single_digits: Option<i64>,
    /// 10: maximum power of ten representable in double precision.
    pub double_max_power: Option<i64>,
    /// 11: significant digits in double precision.
    pub double_digits: Option<i64>,
    /// 12: product identification for the receiving system.
    pub product_id_receiver: Option<String>,
    /// 13: model space scale (model : real world; default 1).
    pub model_scale: Option<f64>,
    /// 14: units flag (1 inch, 2 mm, 3 named in 15, 4 ft, 5 mi, 6 m, 7 km, 8 mil, 9 um,
    /// 10 cm, 11 microinch).
    pub units_flag: Option<i64>,
    /// 15: units name.
    pub units_name: Option<String>,
    /// 16: maximum number of line weight gradations.
    pub line_weight_gradations: Option<i64>,
    /// 17: width of the maximum line weight in units.
    pub max_line_width: Option<f64>,
    /// 18: date and time of file generation (`YYMMDD.HHNNSS` or `YYYYMMDD.HHNNSS`).
    pub date: Option<String>,
    /// 19: minimum user-intended resolution in units.
    pub resolution: Option<f64>,
    /// 20: approximate maximum coordinate value in units.
    pub max_coordinate: Option<f64>,
    /// 21: author.
    pub author: Option<String>,
    /// 22: author's organization.
    pub organization: Option<String>,
    /// 23: IGES version flag (11 = 5.3).
    pub version_flag: Option<i64>,
    /// 24: drafting standard flag.
    pub drafting_standard: Option<i64>,
    /// 25: date and time the model was created or last modified.
    pub modified_date: Option<String>,
    /// 26: application protocol / subset identifier.
    pub application_protocol: Option<String>,
}

impl Global {
    /// The version flag as a name (`IGES 5.3` for 11), when known.
    pub fn version_name(&self) -> Option<&'static str> {
        Some(match self.version_flag? {
            1 => "IGES 1.0",
            2 => "ANSI Y14.26M-1981",
            3 => "IGES 2.0",
            4 => "IGES 3.0",
            5 => "ASME/ANSI Y14.26M-1987",
            6 => "IGES 4.0",
            7 => "ASME Y14.26M-1989",
            8 => "IGES 5.0",
            9 => "IGES 5.1",
            10 => "IGES 5.2",
            11 => "IGES 5.3",
            _ => return None,
        })
    }

    /// The delimiters declared by Global parameters 1 and 2.
    pub fn delimiters(&self) -> Delimiters {
        Delimiters {
            param: self.param_delimiter as u8,
            record: self.record_delimiter as u8,
        }
    }
}
