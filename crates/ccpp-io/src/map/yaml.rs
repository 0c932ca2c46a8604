//! The ROS `map_server` YAML file ([`MapYaml`]).

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;

use super::classify::{MapMode, Thresholds, DEFAULT_FREE_THRESH, DEFAULT_OCCUPIED_THRESH};
use super::error::{one_line, MapError};

/// A parsed and validated ROS `map_server` YAML.
///
/// ```yaml
/// image: map.pgm            # required; relative to the YAML's folder, or absolute
/// resolution: 0.05          # required; metres per pixel, finite and > 0
/// origin: [-10, -10, 0.0]   # required; world pose (x, y, yaw) of the lower-left pixel
/// negate: 0                 # optional, 0/1 or false/true (default 0)
/// occupied_thresh: 0.65     # optional (default 0.65)
/// free_thresh: 0.196        # optional (default 0.196)
/// mode: trinary             # optional: trinary (default), scale or raw
/// ```
///
/// A load's overrides of `resolution` and `origin` (`--resolution`, `--origin`) stand in for
/// those fields, which may then be left out.
///
/// Unknown keys are ignored, as `map_server` does, except one so near a field the file leaves
/// out, with a value that field could take, that it is taken for a misspelling of it
/// ([`MapError::MisspeltField`]: `negat: 1`, `free_threshold: 0.2`, `Origin: [0, 0, 0]`).
#[derive(Clone, Debug, PartialEq)]
pub struct MapYaml {
    /// The image file as written in the YAML (not yet resolved against the YAML's folder).
    pub image: String,
    /// Metres per pixel.
    pub resolution: f64,
    /// World pose `(x, y, yaw)` of the lower-left corner of the lower-left pixel.
    pub origin: [f64; 3],
    /// `true` when the image is negated (`p = v / 255`).
    pub negate: bool,
    /// Occupancy probability above which a pixel is occupied.
    pub occupied_thresh: f64,
    /// Occupancy probability below which a pixel is free.
    pub free_thresh: f64,
    /// The `mode` field when present (`trinary`, `scale` or `raw` in `map_server`).
    pub mode: Option<String>,
}

/// What the YAML holds before the required fields are checked.
#[derive(Deserialize)]
struct RawYaml {
    image: Option<String>,
    resolution: Option<f64>,
    origin: Option<Vec<f64>>,
    negate: Option<Negate>,
    occupied_thresh: Option<f64>,
    free_thresh: Option<f64>,
    mode: Option<String>,
    /// Every other key, with the kind of its value (checked for misspellings of the fields
    /// above).
    #[serde(flatten)]
    other: BTreeMap<String, Loose>,
}

/// The kind of an unknown key's value: enough to tell whether it could be the value of the
/// field the key is near (`moed: raw` is a misspelt `mode`, `model: burger` is not).
#[derive(Clone, Debug, PartialEq)]
enum Loose {
    Bool,
    Number,
    /// A string: its first characters, trimmed and in lower case.
    Text(String),
    List,
    Other,
}

impl<'de> Deserialize<'de> for Loose {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Loose;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("any YAML value")
            }
            fn visit_bool<E: de::Error>(self, _: bool) -> Result<Loose, E> {
                Ok(Loose::Bool)
            }
            fn visit_i64<E: de::Error>(self, _: i64) -> Result<Loose, E> {
                Ok(Loose::Number)
            }
            fn visit_u64<E: de::Error>(self, _: u64) -> Result<Loose, E> {
                Ok(Loose::Number)
            }
            fn visit_f64<E: de::Error>(self, _: f64) -> Result<Loose, E> {
                Ok(Loose::Number)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Loose, E> {
                Ok(Loose::Text(
                    v.trim().chars().take(16).collect::<String>().to_lowercase(),
                ))
            }
            fn visit_unit<E: de::Error>(self) -> Result<Loose, E> {
                Ok(Loose::Other)
            }
            fn visit_none<E: de::Error>(self) -> Result<Loose, E> {
                Ok(Loose::Other)
            }
            fn visit_some<D2: Deserializer<'de>>(self, d: D2) -> Result<Loose, D2::Error> {
                Loose::deserialize(d)
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<Loose, A::Error> {
                while seq.next_element::<de::IgnoredAny>()?.is_some() {}
                Ok(Loose::List)
            }
            fn visit_map<A: de::MapAccess<'de>>(self, mut map: A) -> Result<Loose, A::Error> {
                while map
                    .next_entry::<de::IgnoredAny, de::IgnoredAny>()?
                    .is_some()
                {}
                Ok(Loose::Other)
            }
        }
        deserializer.deserialize_any(V)
    }
}

impl Loose {
    /// Could this be a value of `field`?
    fn fits(&self, field: &str) -> bool {
        match field {
            "image" => matches!(self, Self::Text(_)),
            "origin" => *self == Self::List,
            "negate" => match self {
                Self::Bool | Self::Number => true,
                Self::Text(t) => [
                    "0", "1", "y", "yes", "true", "on", "n", "no", "false", "off",
                ]
                .contains(&t.as_str()),
                _ => false,
            },
            "mode" => {
                matches!(self, Self::Text(t) if ["trinary", "scale", "raw"].contains(&t.as_str()))
            }
            // resolution and the thresholds
            _ => *self == Self::Number,
        }
    }
}

/// The fields of a `map_server` YAML.
const FIELDS: [&str; 7] = [
    "image",
    "resolution",
    "origin",
    "negate",
    "occupied_thresh",
    "free_thresh",
    "mode",
];

/// The field `key` is taken to misspell, if any: the same but for case, one beginning with the
/// other (`negat`, `free_threshold`; at least four letters), or at most two edits apart
/// (`orgin`, `occupied_tresh`).
fn misspelt(key: &str) -> Option<&'static str> {
    let k = key.trim().to_ascii_lowercase();
    if k.chars().count() > 64 {
        // No field is near a key this long (and its edit distance would cost its length
        // times the field's).
        return None;
    }
    FIELDS.into_iter().find(|f| {
        k == *f
            || (k.len() >= 4 && (k.starts_with(f) || f.starts_with(k.as_str())))
            || edits(&k, f) <= 2
    })
}

/// Levenshtein distance of two short ASCII keys.
fn edits(a: &str, b: &str) -> usize {
    // In characters: a zero-width space inside `negate` is one edit, not three bytes.
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let (a, b) = (a.as_slice(), b.as_slice());
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, &ca) in a.iter().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let up = row[j + 1];
            row[j + 1] = (diag + usize::from(ca != cb)).min(up + 1).min(row[j] + 1);
            diag = up;
        }
    }
    row[b.len()]
}

/// `negate` as written: an integer or a boolean.
enum Negate {
    Int(i64),
    Bool(bool),
    Other(String),
}

impl<'de> Deserialize<'de> for Negate {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Negate;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("0, 1, false or true")
            }
            fn visit_bool<E: de::Error>(self, v: bool) -> Result<Negate, E> {
                Ok(Negate::Bool(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Negate, E> {
                Ok(Negate::Int(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Negate, E> {
                Ok(i64::try_from(v).map_or_else(|_| Negate::Other(v.to_string()), Negate::Int))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Negate, E> {
                // `1.0`, not `1` (which would read as accepted).
                Ok(Negate::Other(format!("{v:?}")))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Negate, E> {
                // A quoted scalar, or a word the YAML 1.2 reader leaves as text: Nav2's
                // `map_server` reads `negate` as an integer, else as a yaml-cpp boolean, whose
                // words are y, yes, true and on (n, no, false, off), each in lower case, upper
                // case or capitalised; yaml-cpp reads a quoted scalar as a plain one.
                let t = v.trim();
                let word = |w: &str| {
                    let mut cap = w[..1].to_ascii_uppercase();
                    cap.push_str(&w[1..]);
                    t == w || t == w.to_ascii_uppercase() || t == cap
                };
                Ok(if t == "0" {
                    Negate::Int(0)
                } else if t == "1" {
                    Negate::Int(1)
                } else if ["y", "yes", "true", "on"].into_iter().any(word) {
                    Negate::Bool(true)
                } else if ["n", "no", "false", "off"].into_iter().any(word) {
                    Negate::Bool(false)
                } else {
                    Negate::Other(format!("{v:?}"))
                })
            }
        }
        deserializer.deserialize_any(V)
    }
}

impl MapYaml {
    /// Parses and validates the text of a map YAML. `path` is only used in error messages.
    ///
    /// # Errors
    /// [`MapError::Yaml`] for malformed YAML or wrongly typed fields,
    /// [`MapError::MissingField`] when `image`, `resolution` or `origin` is absent, and
    /// [`MapError::BadValue`] for out-of-domain values (see [`validate_placement`] and
    /// [`Thresholds::validate`]). The mode is not checked here.
    pub fn parse(text: &str, path: &Path) -> Result<Self, MapError> {
        let yaml = Self::parse_fields(text, path, None, None)?;
        yaml.thresholds().validate(path)?;
        Ok(yaml)
    }

    /// [`Self::parse`] without the check of the thresholds, for a load that checks them after
    /// its overrides: `--occupied-thresh 0.3` could not repair a YAML of `occupied_thresh 0.1`
    /// beside `free_thresh 0.196` (the YAML's pair was refused before the override applied).
    /// `resolution` and `origin`, when given, are the load's overrides: they stand in for the
    /// file's fields, which may then be missing or out of their domain (a YAML without
    /// `resolution` was refused as lacking it with `--resolution` given).
    pub(crate) fn parse_fields(
        text: &str,
        path: &Path,
        resolution: Option<f64>,
        origin: Option<[f64; 3]>,
    ) -> Result<Self, MapError> {
        // Let `.nan` / `.inf` through so they are reported as bad values of their field.
        let mut options = serde_saphyr::Options::default();
        options.non_finite_float_policy = serde_saphyr::NonFiniteFloatPolicy::PassThrough;
        // YAML 1.2 booleans only, so that `negate` sees the other words as text and reads
        // them as Nav2's `map_server` does (yaml-cpp's words in its three cases, quoted or
        // not; see `Negate`): YAML 1.1 took `yEs` as true too, and refused a quoted "yes".
        options.strict_booleans = true;
        let raw: RawYaml =
            serde_saphyr::from_str_with_options(text, options).map_err(|e| MapError::Yaml {
                path: path.to_path_buf(),
                message: yaml_message(&e, text),
            })?;
        let missing = |field| MapError::MissingField {
            path: path.to_path_buf(),
            field,
        };
        let bad = |field, reason| MapError::BadValue {
            path: path.to_path_buf(),
            field,
            reason,
        };

        // BTreeMap: the first misspelling in key order, whatever the file's order. Only of a
        // field the file leaves out, and only with a value that field could take: beside
        // `origin`, `origin_frame: map` is another key, and so is `model: burger` or
        // `note: scanned` (refused as a misspelt `origin`, `mode`: hostile pass).
        let given = |f: &str| match f {
            "image" => raw.image.is_some(),
            "resolution" => raw.resolution.is_some(),
            "origin" => raw.origin.is_some(),
            "negate" => raw.negate.is_some(),
            "occupied_thresh" => raw.occupied_thresh.is_some(),
            "free_thresh" => raw.free_thresh.is_some(),
            _ => raw.mode.is_some(),
        };
        if let Some((key, field)) = raw.other.iter().find_map(|(k, v)| {
            misspelt(k)
                .filter(|f| !given(f) && v.fits(f))
                .map(|f| (k, f))
        }) {
            return Err(MapError::MisspeltField {
                path: path.to_path_buf(),
                // Escaped: a tab or an escape sequence in the key was trimmed or printed raw.
                key: key
                    .chars()
                    .take(80)
                    .collect::<String>()
                    .escape_debug()
                    .to_string(),
                field,
            });
        }
        let image = raw.image.ok_or_else(|| missing("image"))?;
        if image.trim().is_empty() {
            return Err(bad("image", "the image file name is empty".to_owned()));
        }
        // A control character would be printed raw in every message naming the image (a
        // newline cut the message short; an escape sequence reached the terminal).
        if let Some(c) = image.chars().find(|c| c.is_control()) {
            return Err(bad(
                "image",
                format!(
                    "the image file name {image:?} holds a control character (U+{:04X})",
                    u32::from(c)
                ),
            ));
        }
        let resolution = match resolution {
            Some(r) => r,
            None => raw.resolution.ok_or_else(|| missing("resolution"))?,
        };
        let origin: [f64; 3] = if let Some(o) = origin {
            o
        } else {
            let origin_v = raw.origin.ok_or_else(|| missing("origin"))?;
            origin_v.as_slice().try_into().map_err(|_| {
                bad(
                    "origin",
                    format!(
                        "expected 3 numbers [x, y, yaw], got {} ({origin_v:?})",
                        origin_v.len()
                    ),
                )
            })?
        };
        let negate = match raw.negate {
            None | Some(Negate::Int(0) | Negate::Bool(false)) => false,
            Some(Negate::Int(1) | Negate::Bool(true)) => true,
            Some(Negate::Int(v)) => return Err(bad("negate", format!("{v} is not 0 or 1"))),
            Some(Negate::Other(v)) => {
                return Err(bad(
                    "negate",
                    format!("{v} is not 0, 1 or a YAML boolean (true/false, yes/no, on/off, y/n)"),
                ))
            }
        };
        let yaml = Self {
            image,
            resolution,
            origin,
            negate,
            occupied_thresh: raw.occupied_thresh.unwrap_or(DEFAULT_OCCUPIED_THRESH),
            free_thresh: raw.free_thresh.unwrap_or(DEFAULT_FREE_THRESH),
            mode: raw.mode,
        };
        validate_placement(yaml.resolution, yaml.origin, path)?;
        Ok(yaml)
    }

    /// The classification thresholds of this YAML.
    pub fn thresholds(&self) -> Thresholds {
        Thresholds {
            occupied: self.occupied_thresh,
            free: self.free_thresh,
            negate: self.negate,
            mode: self
                .mode
                .as_deref()
                .and_then(MapMode::parse)
                .unwrap_or_default(),
        }
    }
}

/// The parser's message without its source snippet, on one line.
fn yaml_message(e: &serde_saphyr::Error, text: &str) -> String {
    let mut opts = serde_saphyr::RenderOptions::default();
    opts.snippets = serde_saphyr::SnippetMode::Off;
    let text = crate::file::yaml_words(&one_line(&e.render_with_options(opts)), text);
    text.strip_prefix("error: ")
        .map(str::to_owned)
        .unwrap_or(text)
}

pub use ccpp_core::geometry::{heading_problem, MAX_HEADING_RAD};

/// Checks that `resolution` is finite and > 0, that `origin` is finite and that its yaw is a
/// heading ([`heading_problem`]).
///
/// # Errors
/// [`MapError::BadValue`] naming `path` and the field.
pub fn validate_placement(resolution: f64, origin: [f64; 3], path: &Path) -> Result<(), MapError> {
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(MapError::BadValue {
            path: path.to_path_buf(),
            field: "resolution",
            reason: format!("{resolution} is not a finite number > 0"),
        });
    }
    if !origin.iter().all(|v| v.is_finite()) {
        return Err(MapError::BadValue {
            path: path.to_path_buf(),
            field: "origin",
            reason: format!("{origin:?} has a non-finite component"),
        });
    }
    if let Some(why) = heading_problem(origin[2]) {
        return Err(MapError::BadValue {
            path: path.to_path_buf(),
            field: "origin",
            reason: format!("yaw {why}"),
        });
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<MapYaml, MapError> {
        MapYaml::parse(text, Path::new("dir/test.yaml"))
    }

    const BASE: &str = "image: m.pgm\nresolution: 0.05\norigin: [-1, -2.5, 0.0]\n";

    #[test]
    fn a_misspelt_field_is_refused_and_other_keys_ignored() {
        for (key, field) in [
            ("negat: 1", "negate"),
            ("Negate: 1", "negate"),
            ("occupied_threshold: 0.5", "occupied_thresh"),
            ("free_tresh: 0.1", "free_thresh"),
            ("moed: raw", "mode"),
            ("Mode: Scale", "mode"),
            ("negat: yes", "negate"),
        ] {
            let e = parse(&format!("{BASE}{key}\n")).unwrap_err();
            assert!(
                matches!(&e, MapError::MisspeltField { field: f, .. } if *f == field),
                "{key}: {e}"
            );
            let msg = e.to_string();
            assert!(msg.contains(key.split(':').next().unwrap()), "{msg}");
            assert!(msg.contains("dir/test.yaml"), "{msg}");
        }
        // A tab and a zero-width space: named escaped, and one edit away.
        for key in ["\"negate\\t\": 1", "\"nega\\u200bte\": 1"] {
            let e = parse(&format!("{BASE}{key}\n")).unwrap_err().to_string();
            assert!(e.contains("did you mean `negate`"), "{e}");
            assert!(e.contains("\\t") || e.contains("\\u{200b}"), "{e}");
        }
        // A key near no field is ignored, as map_server does.
        let y = parse(&format!("{BASE}name: lab\nsensor: lidar\n")).unwrap();
        assert_eq!(y, parse(BASE).unwrap());
        // So is a key near a field the file gives, or with a value that field cannot take:
        // these were refused as misspellings ("did you mean `origin`?" beside `origin`).
        let extra = "origin_frame: map\nimages: [a.png]\nresolution_note: scanned\nnote: scanned 2024\nmodel: burger\nnode: map_server\ncode: 7\nnegative: [1]\n";
        let y = parse(&format!("{BASE}{extra}")).unwrap();
        assert_eq!(y, parse(BASE).unwrap());
        // A misspelt required field the file leaves out is named, not said missing.
        let e = parse("image: m.pgm\nresolution: 0.05\norgin: [0, 0, 0]\n").unwrap_err();
        assert!(e.to_string().contains("did you mean `origin`"), "{e}");
        // A misspelt `image` is named as such, not as a missing field.
        let e = parse("Image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n").unwrap_err();
        assert!(e.to_string().contains("did you mean `image`"), "{e}");
    }

    #[test]
    fn defaults_and_integer_origin() {
        let y = parse(BASE).unwrap();
        assert_eq!(y.image, "m.pgm");
        assert_eq!(y.resolution, 0.05);
        assert_eq!(y.origin, [-1.0, -2.5, 0.0]);
        assert!(!y.negate);
        assert_eq!(y.occupied_thresh, 0.65);
        assert_eq!(y.free_thresh, 0.196);
        assert_eq!(y.mode, None);
    }

    #[test]
    fn negate_forms() {
        // Quoted forms too: yaml-cpp, which `map_server` reads with, converts a quoted scalar
        // as it converts a plain one.
        for (text, want) in [
            ("0", false),
            ("1", true),
            ("false", false),
            ("true", true),
            ("\"0\"", false),
            ("'1'", true),
            ("\"True\"", true),
            // (yaml-cpp's boolean words, which Nav2's map_server falls back to)
            ("y", true),
            ("Yes", true),
            ("ON", true),
            ("\"yes\"", true),
            ("n", false),
            ("No", false),
            ("off", false),
            ("OFF", false),
        ] {
            let y = parse(&format!("{BASE}negate: {text}\n")).unwrap();
            assert_eq!(y.negate, want, "negate: {text}");
        }
        // (mixed case is no yaml-cpp boolean)
        for text in [
            "2", "-1", "0.5", "1.0", "\"2\"", "\"\"", "yEs", "oN", "tRUE", "nO", "\"oFf\"",
        ] {
            let e = parse(&format!("{BASE}negate: {text}\n")).unwrap_err();
            assert!(
                matches!(
                    e,
                    MapError::BadValue {
                        field: "negate",
                        ..
                    }
                ),
                "negate: {text} -> {e}"
            );
            assert!(e.to_string().contains("test.yaml"));
        }
    }

    #[test]
    fn comments_unknown_keys_and_mode() {
        let y = parse(&format!(
            "# licence header\n{BASE}mode: trinary # comment\nextra_key: [1, 2]\n\
             occupied_thresh: 0.7\nfree_thresh: 0.25\n"
        ))
        .unwrap();
        assert_eq!(y.mode.as_deref(), Some("trinary"));
        assert_eq!(
            y.thresholds(),
            Thresholds {
                occupied: 0.7,
                free: 0.25,
                negate: false,
                mode: MapMode::Trinary,
            }
        );
    }

    #[test]
    fn missing_fields() {
        for field in ["image", "resolution", "origin"] {
            let text: String = BASE
                .lines()
                .filter(|l| !l.starts_with(field))
                .flat_map(|l| [l, "\n"])
                .collect();
            let e = parse(&text).unwrap_err();
            assert!(
                matches!(e, MapError::MissingField { field: f, .. } if f == field),
                "{e}"
            );
            let msg = e.to_string();
            assert!(msg.contains("test.yaml") && msg.contains(field), "{msg}");
        }
    }

    #[test]
    fn overrides_stand_in_for_missing_or_bad_placement() {
        let p = Path::new("test.yaml");
        let y =
            MapYaml::parse_fields("image: m.pgm\n", p, Some(0.1), Some([1.0, 2.0, 0.5])).unwrap();
        assert_eq!((y.resolution, y.origin), (0.1, [1.0, 2.0, 0.5]));
        // A value out of its domain (or of the wrong length) is replaced too.
        let text = "image: m.pgm\nresolution: -1\norigin: [0, 0]\n";
        assert!(MapYaml::parse_fields(text, p, None, None).is_err());
        let y = MapYaml::parse_fields(text, p, Some(0.05), Some([0.0; 3])).unwrap();
        assert_eq!((y.resolution, y.origin), (0.05, [0.0; 3]));
        // Only the one given: the other must still be in the file.
        let e = MapYaml::parse_fields("image: m.pgm\n", p, Some(0.1), None).unwrap_err();
        assert!(
            matches!(
                e,
                MapError::MissingField {
                    field: "origin",
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn bad_values() {
        let cases = [
            (
                "image: m.pgm\nresolution: -0.05\norigin: [0, 0, 0]\n",
                "resolution",
            ),
            (
                "image: m.pgm\nresolution: 0\norigin: [0, 0, 0]\n",
                "resolution",
            ),
            (
                "image: m.pgm\nresolution: .nan\norigin: [0, 0, 0]\n",
                "resolution",
            ),
            (
                "image: m.pgm\nresolution: .inf\norigin: [0, 0, 0]\n",
                "resolution",
            ),
            (
                "image: m.pgm\nresolution: 0.1\norigin: [0, .nan, 0]\n",
                "origin",
            ),
            ("image: m.pgm\nresolution: 0.1\norigin: [0, 0]\n", "origin"),
            ("image: ''\nresolution: 0.1\norigin: [0, 0, 0]\n", "image"),
            (&format!("{BASE}occupied_thresh: 1.5\n"), "occupied_thresh"),
            (&format!("{BASE}free_thresh: -0.1\n"), "free_thresh"),
            (&format!("{BASE}free_thresh: 0.7\n"), "free_thresh"),
            (&format!("{BASE}free_thresh: 0.65\n"), "free_thresh"),
        ];
        for (text, field) in cases {
            let e = parse(text).unwrap_err();
            assert!(
                matches!(e, MapError::BadValue { field: f, .. } if f == field),
                "{text:?} -> {e}"
            );
            let msg = e.to_string();
            assert!(msg.contains("test.yaml") && !msg.contains('\n'), "{msg}");
        }
    }

    #[test]
    fn malformed_yaml_is_one_line() {
        for text in [
            "image: [unclosed\nresolution: 0.05\n",
            "resolution: abc\nimage: m.pgm\norigin: [0, 0, 0]\n",
            "- a\n- b\n",
            "\u{0}\u{1}",
        ] {
            let e = parse(text).unwrap_err();
            assert!(matches!(e, MapError::Yaml { .. }), "{text:?} -> {e}");
            let msg = e.to_string();
            assert!(msg.contains("test.yaml") && !msg.contains('\n'), "{msg}");
        }
    }
}
