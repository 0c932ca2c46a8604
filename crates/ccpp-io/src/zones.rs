//! Zone files for `--area` and `--keepout` ([`ccpp_core::zones`] holds the semantics):
//!
//! * **`GeoJSON`** (`.geojson` / `.json`): a `Polygon`, `MultiPolygon`, `Feature`,
//!   `FeatureCollection` or `GeometryCollection` of them, in **map coordinates** (metres, the
//!   map's frame; `[x, y]` order, a third coordinate ignored). Only outer rings: a polygon with
//!   holes is refused (give the hole's surroundings as separate polygons).
//! * **YAML polygon lists** (`.yaml` / `.yml` without an `image` key): one polygon as a list of
//!   points, or a list of polygons; a point is `[x, y]` or `{x: .., y: ..}`; a top-level
//!   `polygons:` key holding such a list is accepted too.
//! * **Nav2 keepout filter masks** (keep-out only): a `map_server` YAML (with an `image` key) and
//!   its image in the map's frame, read by the map loader with the mask's own thresholds:
//!   occupied pixels are keep-out. The mask must have exactly the map's size, resolution and
//!   origin; anything else is refused (a mask in another frame would forbid the wrong floor).

use ccpp_core::display::{join, Compact};
use std::path::{Path, PathBuf};

use ccpp_core::grid::MapFrame;
use ccpp_core::zones::Polygon;
use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::map::{load_map, one_line, LoadOptions, MapYaml};

/// Where a zone comes from (serialized untagged: `[x0, y0, x1, y1]`, a file name, or a list of
/// polygons, each a list of `[x, y]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ZoneSpec {
    /// The axis-aligned rectangle `[x0, y0, x1, y1]`, map coordinates.
    Rect([f64; 4]),
    /// Polygons given inline, map coordinates.
    Polygons(Vec<Polygon>),
    /// A polygon file (`GeoJSON` or YAML) or, for keep-outs, a Nav2 keepout filter mask.
    File(PathBuf),
}

/// What a zone file holds.
#[derive(Clone, Debug)]
pub enum ZoneData {
    /// Polygons in map coordinates.
    Polygons(Vec<Polygon>),
    /// A keep-out pixel mask on the map grid (occupied pixels of a Nav2 mask).
    Mask(FixedBitSet),
}

/// Error reading a zone file (the message never names the file: the caller adds it).
#[derive(Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ZoneFileError(pub String);

fn bad(m: impl Into<String>) -> ZoneFileError {
    ZoneFileError(m.into())
}

/// A zone as the command line and Python take it as text: four comma-separated numbers are the
/// rectangle `X0,Y0,X1,Y1` (spaces around the numbers allowed), anything else names a file
/// (other counts of comma-separated numbers only when such a file exists).
/// The rectangle's values are checked where every zone is ([`ZoneSpec::load`] through the
/// scenario), so `"nan,0,1,1"` parses here and is refused there.
///
/// ```
/// use ccpp_io::zones::ZoneSpec;
/// assert_eq!("0, 1, 2.5, 3".parse(), Ok(ZoneSpec::Rect([0.0, 1.0, 2.5, 3.0])));
/// assert_eq!("rug.geojson".parse(), Ok(ZoneSpec::File("rug.geojson".into())));
/// // Numbers, but not four, that name no file: a mistyped rectangle.
/// assert!("1,2,3".parse::<ZoneSpec>().is_err());
/// assert!("".parse::<ZoneSpec>().is_err());
/// ```
impl std::str::FromStr for ZoneSpec {
    type Err = ZoneFileError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let numbers: Result<Vec<f64>, _> = s.split(',').map(|p| p.trim().parse::<f64>()).collect();
        if let Ok(Ok(r)) = numbers.map(<[f64; 4]>::try_from) {
            // A file of that very name was ignored in silence.
            if Path::new(s).exists() {
                return Err(bad(format!(
                    "{s:?} reads as the rectangle X0,Y0,X1,Y1 and names a file too: give the file as ./{s}, or rename it"
                )));
            }
            return Ok(Self::Rect(r));
        }
        if s.is_empty() {
            return Err(bad("expected a file or X0,Y0,X1,Y1, got an empty value"));
        }
        // Numbers, but not four of them, and no such file: a mistyped rectangle (it was
        // reported as a missing file `/cwd/1,1,2,2,3`).
        let parts: Vec<&str> = s.split(',').collect();
        if parts.len() > 1
            && parts.iter().all(|p| p.trim().parse::<f64>().is_ok())
            && !Path::new(s).exists()
        {
            return Err(bad(format!(
                "expected a file or X0,Y0,X1,Y1 (four numbers), got {} numbers: {s:?}",
                parts.len()
            )));
        }
        Ok(Self::File(PathBuf::from(s)))
    }
}

impl ZoneSpec {
    /// The same zone with a file named by its absolute path (made from the working folder),
    /// as `run.json` records zone files so that a run replays from any folder. Symbolic links
    /// are kept, not resolved: a mask YAML's image is looked up beside the path given, as
    /// `map_server` does.
    #[must_use]
    pub fn absolute(self) -> Self {
        match self {
            ZoneSpec::File(p) => ZoneSpec::File(std::path::absolute(&p).unwrap_or(p)),
            other => other,
        }
    }

    /// The file this spec names, if any.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Self::File(p) => Some(p),
            _ => None,
        }
    }

    /// Short description for messages and `info`: the file name, `rectangle` or `inline`.
    pub fn label(&self) -> String {
        match self {
            Self::Rect(r) => format!("rectangle {}", join(r)),
            Self::Polygons(p) => format!("{} inline polygon(s)", p.len()),
            Self::File(p) => p.display().to_string(),
        }
    }

    /// Loads the zone for a map of frame `frame`; `mask_ok` allows Nav2 masks (keep-outs).
    /// Polygons are validated.
    ///
    /// # Errors
    /// An unreadable or malformed file, an invalid polygon, a mask in another frame, or a mask
    /// where it is not allowed.
    pub fn load(&self, frame: &MapFrame, mask_ok: bool) -> Result<ZoneData, ZoneFileError> {
        let polys = match self {
            Self::Rect(r) => {
                check_rect(*r)?;
                vec![Polygon::rect(*r)]
            }
            Self::Polygons(p) => p.clone(),
            // (`read_file` gives a mask only where `mask_ok` allows one)
            Self::File(path) => match read_file(path, frame, mask_ok)? {
                ZoneData::Mask(m) => return Ok(ZoneData::Mask(m)),
                ZoneData::Polygons(p) => p,
            },
        };
        ccpp_core::zones::validate_polygons(&polys).map_err(|e| bad(e.to_string()))?;
        Ok(ZoneData::Polygons(polys))
    }
}

/// Why a mask is no area.
const AREA_NOT_MASK: &str = "is a keepout mask; an area must be polygons (GeoJSON or a YAML list \
                             of x,y points) or a rectangle X0,Y0,X1,Y1";

/// Checks a rectangle `[x0, y0, x1, y1]`: finite with `x1 > x0` and `y1 > y0`.
///
/// # Errors
/// The rectangle is empty or not finite.
pub fn check_rect(r: [f64; 4]) -> Result<(), ZoneFileError> {
    if r.iter().any(|v| !v.is_finite()) {
        return Err(bad(format!("rectangle {} must be finite", join(&r))));
    }
    if !(r[2] > r[0] && r[3] > r[1]) {
        return Err(bad(format!(
            "rectangle {} is empty: it needs X1 > X0 and Y1 > Y0",
            join(&r)
        )));
    }
    Ok(())
}

/// Most points a zone file (`GeoJSON` or YAML) may hold in all (16 polygons of the most points
/// one polygon may have, [`ccpp_core::zones::MAX_POLYGON_POINTS`]).
pub const MAX_ZONE_POINTS: usize = 16 * ccpp_core::zones::MAX_POLYGON_POINTS;

/// Reads a zone file: `GeoJSON`, YAML polygons or a Nav2 mask (checked against `frame`);
/// `mask_ok`: a mask may be given (a keep-out), which the messages for an image tell.
fn read_file(path: &Path, frame: &MapFrame, mask_ok: bool) -> Result<ZoneData, ZoneFileError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let bytes = crate::file::read_bytes(path).map_err(|e| bad(e.to_string()))?;
    // A mask's image given instead of its YAML was refused as "stream did not contain valid
    // UTF-8" (a binary file) or as a YAML error (a plain PGM).
    if ["png", "pgm", "pnm", "ppm", "pbm", "pam"].contains(&ext.as_str()) || is_image(&bytes) {
        return Err(bad(if mask_ok {
            "is an image; zones are GeoJSON or YAML polygons, and a keepout mask is given by \
             its map_server YAML (image, resolution, origin in the map's frame), not by the \
             bare image"
        } else {
            "is an image; an area must be polygons (GeoJSON or a YAML list of x,y points) or a \
             rectangle X0,Y0,X1,Y1"
        }));
    }
    let text = crate::file::text_of(bytes).ok_or_else(|| {
        bad(if mask_ok {
            "is not a text file; a zone file is GeoJSON, a YAML list of polygons or a Nav2 \
             mask's map_server YAML"
        } else {
            "is not a text file; an area file is GeoJSON or a YAML list of polygons"
        })
    })?;
    let yaml_ext = ext == "yaml" || ext == "yml";
    if ext == "geojson" || ext == "json" || (!yaml_ext && text.trim_start().starts_with('{')) {
        // Counted before parsing (every point opens a `[`, or a `{` when written as
        // `{"x": .., "y": ..}`): a file of 625 polygons of 4001 points (58 MB) parsed to 550 MB
        // and took 27 s to draw, in a run admitted under 140 MB.
        let opens = text.bytes().filter(|&b| b == b'[' || b == b'{').count();
        if opens > 2 * MAX_ZONE_POINTS {
            return Err(bad(format!(
                "GeoJSON: more than {MAX_ZONE_POINTS} points in all (about {opens} arrays); a site's zones have hundreds"
            )));
        }
        let v: Value = serde_json::from_str(&text).map_err(|e| bad(format!("GeoJSON: {e}")))?;
        let role = if mask_ok { "keepout" } else { "area" };
        return within_total(geojson_polygons_as(&v, role)?, "GeoJSON");
    }
    let v: serde_json::Value = serde_saphyr::from_str(&text).map_err(|e| {
        bad(format!(
            "YAML: {}",
            crate::file::yaml_words(&e.to_string(), &text)
        ))
    })?;
    if v.get("image").is_some() {
        if !mask_ok {
            return Err(bad(AREA_NOT_MASK));
        }
        // Loaded as a map, which is read as a YAML by its name only: a mask YAML named
        // `mask.txt` was decoded as an image ("not a PNG or PNM/PGM image").
        if !yaml_ext {
            return Err(bad(
                "holds a Nav2 mask's map_server YAML (an `image` key) but its name does not \
                 end in .yaml or .yml, which a map_server YAML's must; rename it",
            ));
        }
        return read_mask(path, frame).map(ZoneData::Mask);
    }
    within_total(yaml_polygons(&v)?, "YAML")
}

/// Whether `bytes` begin as an image file does: the PNG signature, or a PNM's `P1`..`P7`
/// followed by whitespace.
fn is_image(bytes: &[u8]) -> bool {
    bytes.starts_with(b"\x89PNG\r\n\x1a\n")
        || matches!(bytes, [b'P', b'1'..=b'7', w, ..] if w.is_ascii_whitespace())
}

/// The polygons of a zone file, if they hold at most [`MAX_ZONE_POINTS`] vertices in all,
/// counted as each polygon's own limit counts them (16 closed rings of the most vertices a
/// polygon may have were refused for their closing repeats); `format` names the file's kind.
fn within_total(polygons: Vec<Polygon>, format: &str) -> Result<ZoneData, ZoneFileError> {
    let points: usize = polygons.iter().map(Polygon::vertex_count).sum();
    if points > MAX_ZONE_POINTS {
        return Err(bad(format!(
            "{format}: {points} points in all; at most {MAX_ZONE_POINTS} are accepted"
        )));
    }
    Ok(ZoneData::Polygons(polygons))
}

fn read_mask(path: &Path, frame: &MapFrame) -> Result<FixedBitSet, ZoneFileError> {
    let size_err = |w: usize, h: usize| {
        bad(format!(
            "keepout mask is {w} x {h} px but the map is {} x {} px; a mask must be in the map's frame",
            frame.width, frame.height
        ))
    };
    // The size is in the image header: a mask of another size is refused before its pixels
    // are decoded (a huge or foreign mask costs nothing). Any problem reading the header is
    // left to the loader below, which reports it properly.
    if let Some((w, h)) = mask_image_size(path) {
        if (w, h) != (frame.width, frame.height) {
            return Err(size_err(w, h));
        }
    }
    // At most the map's own pixels, which the memory limit has admitted: with no budget the
    // decoder kept its default cap of 512 MiB, and a 16-bit RGBA mask of an 8500 x 8500 px
    // map was refused at any --max-memory ("Memory limit exceeded"; hostile pass).
    let opts = LoadOptions {
        max_pixels: Some(frame.len() as u64),
        ..LoadOptions::default()
    };
    let m = load_map(path, &opts).map_err(|e| bad(e.to_string()))?;
    let f = *m.grid.frame();
    if f.width != frame.width || f.height != frame.height {
        return Err(size_err(f.width, f.height));
    }
    // The same frame to a thousandth of a pixel anywhere on the map: a mask written with its
    // origin in single precision (-3.0999999 for -3.1) or printed to six decimals was refused
    // for 2e-5 px (the test was relative, 1e-9).
    let res = frame.resolution;
    let extent = frame.width.max(frame.height).max(1) as f64;
    let tol_px = 1e-3;
    let same_res = (f.resolution - res).abs() * extent <= tol_px * res;
    let close = |a: f64, b: f64| (a - b).abs() <= tol_px * res;
    let same_yaw = {
        let d = (f.origin.theta - frame.origin.theta).rem_euclid(std::f64::consts::TAU);
        d.min(std::f64::consts::TAU - d) * extent <= tol_px
    };
    if !same_res {
        return Err(bad(format!(
            "keepout mask resolution {} m/px differs from the map's {} m/px; a mask must be in the map's frame",
            Compact(f.resolution),
            Compact(frame.resolution)
        )));
    }
    let (o, p) = (f.origin, frame.origin);
    if !(close(o.x, p.x) && close(o.y, p.y) && same_yaw) {
        return Err(bad(format!(
            "keepout mask origin [{}] differs from the map's [{}]; a mask must be in the map's frame",
            join(&[o.x, o.y, o.theta]),
            join(&[p.x, p.y, p.theta])
        )));
    }
    let mut bits = FixedBitSet::with_capacity(f.len());
    for (i, c) in m.grid.cells().iter().enumerate() {
        if *c == ccpp_core::Cell::Occupied {
            bits.insert(i);
        }
    }
    Ok(bits)
}

/// Width and height of a mask's image from its header alone (`None` when the YAML or the
/// header cannot be read; the full load then says why).
fn mask_image_size(yaml: &Path) -> Option<(usize, usize)> {
    let text = crate::file::read_text(yaml).ok()?;
    let y = MapYaml::parse(&text, yaml).ok()?;
    let image = yaml.parent().unwrap_or(Path::new("")).join(&y.image);
    let file = crate::file::open_regular(&image).ok()?;
    let (w, h) = crate::map::pixels::header_size(std::io::BufReader::new(file))?;
    Some((usize::try_from(w).ok()?, usize::try_from(h).ok()?))
}

/// A key of a zone file as a message shows it: its first `max` characters, escaped.
fn key_text(k: &str, max: usize) -> String {
    k.chars()
        .take(max)
        .collect::<String>()
        .escape_debug()
        .to_string()
}

/// A point of a zone file: `[x, y]` or `{x: .., y: ..}`; in `GeoJSON` (`geo`) a position may
/// carry a third coordinate (altitude, ignored). Anything more is refused: a YAML row
/// `[0, -4, 2, -4]` (two points written on one line) was read as its first point, in silence.
fn point(v: &Value, geo: bool) -> Result<[f64; 2], ZoneFileError> {
    let num = |x: &Value| {
        x.as_f64()
            .ok_or_else(|| bad(format!("coordinate {x} is not a number")))
    };
    let most = if geo { 3 } else { 2 };
    match v {
        Value::Array(a) if (2..=most).contains(&a.len()) => {
            // An altitude is a number too (RFC 7946, 3.1.1): `[x, y, null]` or `[x, y, "a"]`
            // was taken in silence.
            if let Some(z) = a.get(2) {
                num(z)?;
            }
            Ok([num(&a[0])?, num(&a[1])?])
        }
        Value::Array(a) if a.len() > most => Err(bad(format!(
            "point [{}{}] has {} {}; a point is {}",
            a.iter()
                .take(4)
                .map(Value::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            if a.len() > 4 { ", ..." } else { "" },
            a.len(),
            // (a list nested once too deep is a point of lists, not of numbers)
            if a.iter().all(Value::is_number) {
                "numbers"
            } else {
                "items"
            },
            if geo { "[x, y] or [x, y, z]" } else { "[x, y]" }
        ) + if a.iter().any(Value::is_array) {
            " (a level of brackets too many?)"
        } else {
            ""
        })),
        // (`z` too, as a `geometry_msgs/Point32` list is dumped, when it is a number: the
        // plane's zones ignore it, as a GeoJSON position's third number)
        Value::Object(o) => match (o.get("x"), o.get("y")) {
            (Some(x), Some(y))
                if o.len() == 2 || (o.len() == 3 && o.get("z").is_some_and(Value::is_number)) =>
            {
                Ok([num(x)?, num(y)?])
            }
            // `z` allowed but not a number: that is the problem (it was named as a key
            // other than x and y: hostile pass).
            (Some(_), Some(_)) if o.len() == 3 && o.get("z").is_some_and(|z| !z.is_number()) => {
                Err(bad(format!(
                    "point's z must be a number (it is ignored), got {}",
                    o.get("z").map_or_else(String::new, Value::to_string)
                )))
            }
            (Some(_), Some(_)) => Err(bad(format!(
                "point has keys other than x, y and z: {}",
                o.keys()
                    .filter(|k| !matches!(k.as_str(), "x" | "y" | "z"))
                    .take(3)
                    .map(|k| key_text(k, 40))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
            _ => Err(bad(format!("point {v} needs x and y"))),
        },
        _ => Err(bad(format!("point {v} is not [x, y]"))),
    }
}

fn ring(v: &Value, geo: bool) -> Result<Polygon, ZoneFileError> {
    let Value::Array(a) = v else {
        return Err(bad(format!("a polygon must be a list of points, got {v}")));
    };
    Ok(Polygon {
        points: a.iter().map(|p| point(p, geo)).collect::<Result<_, _>>()?,
        name: None,
    })
}

fn is_point(v: &Value) -> bool {
    match v {
        // (a scalar first: a point, even when it is not a number, so that a quoted `"0"` is
        // reported as a coordinate that is not a number, not as a mix of the two forms)
        Value::Array(a) => a.first().is_some_and(|c| !c.is_array() && !c.is_object()),
        Value::Object(o) => o.contains_key("x"),
        _ => false,
    }
}

/// What a YAML zone file that mixes a polygon's points and lists of points should be.
const MIXED_FORMS: &str =
    "give one polygon as a list of x,y points, or several as a list of such lists";

/// Polygons of a YAML polygon list (one polygon, a list of them, or `polygons: [...]`).
fn yaml_polygons(v: &Value) -> Result<Vec<Polygon>, ZoneFileError> {
    // A misspelt or foreign key beside `polygons` (`frame: odom`, `keepout: false`) would be
    // ignored with what it meant.
    if let Value::Object(o) = v {
        if let Some(k) = o.keys().find(|k| k.as_str() != "polygons") {
            let k = key_text(k, 80);
            return Err(bad(format!(
                "unknown key `{k}`: a YAML zone file is a list of x,y points, a list of such lists, `polygons:` with such lists, or a map_server YAML (keepout mask)"
            )));
        }
    }
    let v = v.get("polygons").unwrap_or(v);
    let Value::Array(a) = v else {
        return Err(bad(
            "expected a list of x,y points, a list of such lists, or a map_server YAML (keepout mask)",
        ));
    };
    if a.is_empty() {
        return Ok(Vec::new());
    }
    if is_point(&a[0]) {
        // One polygon: an item that is itself a list of points mixes the two forms (it was
        // read as "point [[2, 2], [3, 2]] has 2 numbers").
        if let Some(k) = a
            .iter()
            .position(|p| matches!(p, Value::Array(q) if q.first().is_some_and(is_point)))
        {
            return Err(bad(format!(
                "item {} is a list of points while item 1 is a point: {MIXED_FORMS}",
                k + 1
            )));
        }
        return Ok(vec![ring(v, false)?]);
    }
    // Several polygons: a point among them mixes the two forms the other way.
    if let Some(k) = a.iter().position(is_point) {
        return Err(bad(format!(
            "item {} is a point while item 1 is a list of points: {MIXED_FORMS}",
            k + 1
        )));
    }
    a.iter().map(|r| ring(r, false)).collect()
}

/// Polygons of a `GeoJSON` object.
#[cfg(test)]
fn geojson_polygons(v: &Value) -> Result<Vec<Polygon>, ZoneFileError> {
    let mut out = Vec::new();
    geojson_collect(v, &mut out, 0, &mut Kinds::default())?;
    Ok(out)
}

/// What a `GeoJSON` zone file's features say they are (their `kind` property, as ccpp's
/// exports write it: `area`, `keepout`, `path`), and which ones are taken.
#[derive(Default)]
struct Kinds<'a> {
    /// The role the file is read in (`area` or `keepout`); `None` takes every polygon.
    role: Option<&'a str>,
    /// Features left out for another zone kind.
    other: usize,
}

/// Polygons of a `GeoJSON` object read as zones of `role` (`area` or `keepout`): features
/// whose `kind` property names the other role, or `path`, are left out. ccpp's own
/// `path.geojson` (the path and both kinds of zones) was refused for its path, and without
/// the path its keep-outs were read as area (or the area as a keep-out), in silence.
fn geojson_polygons_as(v: &Value, role: &str) -> Result<Vec<Polygon>, ZoneFileError> {
    let mut out = Vec::new();
    let mut kinds = Kinds {
        role: Some(role),
        other: 0,
    };
    geojson_collect(v, &mut out, 0, &mut kinds)?;
    if out.is_empty() && kinds.other > 0 {
        let other = if role == "area" { "keepout" } else { "area" };
        return Err(bad(format!(
            "GeoJSON: no feature of kind \"{role}\", only {} of kind \"{other}\" (the kind property of ccpp's exports); give it as --{other}",
            kinds.other
        )));
    }
    Ok(out)
}

fn geojson_polygon(rings: &Value, out: &mut Vec<Polygon>) -> Result<(), ZoneFileError> {
    let Value::Array(r) = rings else {
        return Err(bad("GeoJSON Polygon coordinates must be a list of rings"));
    };
    // Rings of positions (`[[x, y], ...]`): a list of positions instead is a level of
    // brackets short (as in a MultiPolygon written like a Polygon), not a polygon with holes.
    if r.iter()
        .any(|ring| matches!(ring, Value::Array(pts) if pts.first().is_some_and(Value::is_number)))
    {
        return Err(bad(
            "GeoJSON polygon coordinates must be a list of rings, each a list of [x, y] points: this one is a list of points, a level of brackets short (a MultiPolygon's coordinates are a list of polygons, [[[[x, y], ...]]])",
        ));
    }
    if r.len() > 1 {
        return Err(bad(
            "GeoJSON polygon with holes: not supported; give the zone as polygons without holes",
        ));
    }
    if let Some(outer) = r.first() {
        out.push(ring(outer, true)?);
    }
    Ok(())
}

fn geojson_collect(
    v: &Value,
    out: &mut Vec<Polygon>,
    depth: usize,
    kinds: &mut Kinds<'_>,
) -> Result<(), ZoneFileError> {
    if depth > 8 {
        return Err(bad("GeoJSON nested too deeply"));
    }
    // The 2008 GeoJSON's `crs` member: a named CRS (EPSG:4326 latitude/longitude, a UTM zone)
    // is not the map's frame (`"crs": null`, no CRS, is no claim), and reading its numbers as metres in the map put the zone
    // anywhere, silently. RFC 7946 dropped the member; ccpp's own exports never write it.
    if let Some(crs) = v.get("crs").filter(|c| !c.is_null()) {
        let name = crs
            .pointer("/properties/name")
            .and_then(Value::as_str)
            .map_or_else(|| one_line(&crs.to_string()), one_line);
        let name: String = name.chars().take(80).collect();
        return Err(bad(format!(
            "GeoJSON crs {name:?}: zones are read in map coordinates (metres in the map YAML's frame, as ccpp's exports write them); convert the file to map coordinates and leave out \"crs\""
        )));
    }
    let ty = v.get("type").and_then(Value::as_str).unwrap_or("");
    let coords = || {
        v.get("coordinates").ok_or_else(|| {
            bad(format!(
                "GeoJSON {} without coordinates",
                crate::message::visible(ty)
            ))
        })
    };
    match ty {
        "Polygon" => geojson_polygon(coords()?, out),
        "MultiPolygon" => match coords()? {
            // A member without rings is no polygon (RFC 7946 3.1.7): it was skipped in
            // silence, and the zone was the other members alone.
            Value::Array(ps) => ps.iter().enumerate().try_for_each(|(k, p)| {
                if matches!(p, Value::Array(r) if r.is_empty()) {
                    return Err(bad(format!(
                        "GeoJSON MultiPolygon member {} has no ring; each member is a polygon's list of rings",
                        k + 1
                    )));
                }
                geojson_polygon(p, out)
            }),
            _ => Err(bad("GeoJSON MultiPolygon coordinates must be a list")),
        },
        "Feature" => match v.get("geometry") {
            Some(g) if !g.is_null() => {
                // (matched whatever its case: a hand-written `"Keepout"` was taken as area)
                let kind = v
                    .pointer("/properties/kind")
                    .and_then(Value::as_str)
                    .map(str::to_ascii_lowercase);
                if let (Some(role), Some(kind)) = (kinds.role, kind.as_deref()) {
                    if kind == "path" {
                        return Ok(());
                    }
                    if ["area", "keepout"].contains(&kind) && kind != role {
                        kinds.other += 1;
                        return Ok(());
                    }
                }
                let first = out.len();
                geojson_collect(g, out, depth + 1, kinds)?;
                // The feature's name names every polygon of its geometry.
                // A number or a boolean names it as written; a list or an object is no name.
                let name = match v.get("properties").and_then(|p| p.get("name")) {
                    Some(Value::String(s)) => Some(s.clone()),
                    Some(n @ (Value::Number(_) | Value::Bool(_))) => Some(n.to_string()),
                    _ => None,
                };
                if let Some(name) = name {
                    for p in &mut out[first..] {
                        p.name = Some(name.clone());
                    }
                }
                Ok(())
            }
            _ => Ok(()),
        },
        "FeatureCollection" => match v.get("features") {
            Some(Value::Array(fs)) => fs
                .iter()
                .try_for_each(|f| geojson_collect(f, out, depth + 1, kinds)),
            _ => Err(bad("GeoJSON FeatureCollection without a features list")),
        },
        "GeometryCollection" => match v.get("geometries") {
            Some(Value::Array(gs)) => gs
                .iter()
                .try_for_each(|g| geojson_collect(g, out, depth + 1, kinds)),
            _ => Err(bad("GeoJSON GeometryCollection without a geometries list")),
        },
        "" => Err(bad("not GeoJSON: no \"type\"")),
        other => Err(bad(format!(
            "GeoJSON {} is not a zone: use Polygon, MultiPolygon, Feature or FeatureCollection",
            crate::message::visible(other)
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `GeoJSON` position's third member is an altitude, a number: `null`, text, objects
    /// and lists there were taken in silence. A file saved with a byte order mark is read
    /// (it was refused at "line 1 column 1"; named `.txt`, read as YAML).
    #[test]
    fn geojson_altitudes_are_numbers_and_a_byte_order_mark_is_skipped() {
        let d = tempfile::tempdir().unwrap();
        let frame = MapFrame::new(10, 10, 1.0);
        let poly = |z: &str| {
            format!("{{\"type\":\"Polygon\",\"coordinates\":[[[1,1{z}],[3,1],[3,3],[1,1]]]}}")
        };
        let path = d.path().join("z.geojson");
        for z in [",null", ",\"a\"", ",{}", ",[1]"] {
            std::fs::write(&path, poly(z)).unwrap();
            let e = read_file(&path, &frame, true).unwrap_err().to_string();
            assert!(e.contains("is not a number"), "{z}: {e}");
        }
        std::fs::write(&path, poly(",2.5")).unwrap();
        assert!(read_file(&path, &frame, true).is_ok());
        for name in ["bom.geojson", "bom.txt"] {
            let path = d.path().join(name);
            std::fs::write(&path, format!("\u{feff}{}", poly(""))).unwrap();
            match read_file(&path, &frame, true) {
                Ok(ZoneData::Polygons(p)) => assert_eq!(p.len(), 1, "{name}"),
                other => panic!("{name}: {other:?}"),
            }
        }
    }

    /// A zone file's total counts vertices as each polygon's limit does: 16 closed `GeoJSON`
    /// rings of the most vertices a polygon may have were refused (65 552 "points") for their
    /// closing repeats; 17 such rings are still too many, in `GeoJSON` and in YAML.
    #[test]
    fn the_total_limit_does_not_count_closing_repeats() {
        let n = ccpp_core::zones::MAX_POLYGON_POINTS;
        let file = |rings: usize| {
            let ring = |k: usize| {
                let mut pts: Vec<String> = (0..n)
                    .map(|i| {
                        let a = std::f64::consts::TAU * i as f64 / n as f64;
                        format!("[{},{}]", 10.0 * k as f64 + a.cos(), a.sin())
                    })
                    .collect();
                pts.push(pts[0].clone());
                format!("[[{}]]", pts.join(","))
            };
            let polys: Vec<String> = (0..rings).map(ring).collect();
            format!(
                "{{\"type\":\"MultiPolygon\",\"coordinates\":[{}]}}",
                polys.join(",")
            )
        };
        let d = tempfile::tempdir().unwrap();
        let frame = MapFrame::new(10, 10, 1.0);
        let path = d.path().join("z.geojson");
        std::fs::write(&path, file(16)).unwrap();
        match read_file(&path, &frame, true) {
            Ok(ZoneData::Polygons(p)) => assert_eq!(p.len(), 16),
            other => panic!("{other:?}"),
        }
        std::fs::write(&path, file(17)).unwrap();
        let e = read_file(&path, &frame, true).unwrap_err().to_string();
        assert!(e.contains("69632 points in all"), "{e}");
        // A YAML zone file is held to the same total (only its parser's node budget bounded it).
        let yaml = |rings: usize| {
            let ring = (0..n)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / n as f64;
                    format!("[{},{}]", a.cos(), a.sin())
                })
                .collect::<Vec<_>>()
                .join(",");
            format!("- [{ring}]\n").repeat(rings)
        };
        let path = d.path().join("z.yaml");
        std::fs::write(&path, yaml(16)).unwrap();
        assert!(read_file(&path, &frame, true).is_ok());
        std::fs::write(&path, yaml(17)).unwrap();
        let e = read_file(&path, &frame, true).unwrap_err().to_string();
        assert!(e.contains("YAML: 69632 points in all"), "{e}");
    }

    /// A YAML point is `[x, y]` or `{x, y}` and nothing more; a `GeoJSON` position may add
    /// an altitude. A row `[0, -4, 2, -4]` (two points on one line) was read as `[0, -4]`.
    /// A feature's `kind` is matched whatever its case: a hand-written `"Keepout"` was read as
    /// area (`--area` took the keep-out's polygon as part of the work area).
    #[test]
    fn feature_kinds_match_whatever_their_case() {
        let v: Value = serde_json::from_str(
            r#"{"type":"FeatureCollection","features":[
              {"type":"Feature","properties":{"kind":"Area"},"geometry":{"type":"Polygon","coordinates":[[[0,0],[4,0],[4,4],[0,0]]]}},
              {"type":"Feature","properties":{"kind":"Keepout"},"geometry":{"type":"Polygon","coordinates":[[[1,1],[2,1],[2,2],[1,1]]]}},
              {"type":"Feature","properties":{"kind":"PATH"},"geometry":{"type":"Polygon","coordinates":[[[5,5],[6,5],[6,6],[5,5]]]}}]}"#,
        )
        .unwrap();
        let area = geojson_polygons_as(&v, "area").unwrap();
        assert_eq!(area.len(), 1);
        assert_eq!(area[0].points[1], [4.0, 0.0]);
        let keep = geojson_polygons_as(&v, "keepout").unwrap();
        assert_eq!(keep.len(), 1);
        assert_eq!(keep[0].points[1], [2.0, 1.0]);
    }

    #[test]
    fn points_with_more_numbers_are_refused() {
        let yaml = |t: &str| yaml_polygons(&serde_saphyr::from_str::<Value>(t).unwrap());
        let geo = |t: &str| geojson_polygons(&serde_json::from_str::<Value>(t).unwrap());
        let e = yaml(
            "- [0, -4, 2, -4]
- [2, -2, 0, -2]
- [1, -1, 5, 5]
",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("[0, -4, 2, -4] has 4 numbers"), "{e}");
        assert!(yaml(
            "- [0, 0, 1]
- [1, 0]
- [1, 1]
"
        )
        .is_err());
        // A keyed z (a `geometry_msgs/Point32` list as ROS dumps it) is an altitude, left
        // out as a GeoJSON position's; any other key, or a z that is no number, is refused.
        let p = yaml(
            "- {x: 0, y: 0, z: 1}
- {x: 1, y: 0, z: 0.0}
- {x: 1, y: 1}
",
        )
        .unwrap();
        assert_eq!(p[0].points, [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]);
        for (bad, says) in [
            // (the z named as a key other than x and y: hostile pass)
            (
                "{x: 0, y: 0, z: up}",
                "point's z must be a number (it is ignored), got \"up\"",
            ),
            ("{x: 0, y: 0, w: 1}", "keys other than x, y and z: w"),
            ("{x: 0, y: 0, z: 1, w: 1}", "keys other than x, y and z: w"),
        ] {
            let e = yaml(&format!("- {bad}\n- {{x: 1, y: 0}}\n- {{x: 1, y: 1}}\n"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(says), "{bad}: {e}");
        }
        // A MultiPolygon a level of brackets short is told as such, not as holes.
        let e = geo(r#"{"type":"MultiPolygon","coordinates":[[[2,-4],[4,-4],[4,-1],[2,-4]]]}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a level of brackets short"), "{e}");
        assert_eq!(
            yaml(
                "- [0, 0]
- [1, 0]
- [1, 1]
"
            )
            .unwrap()
            .len(),
            1
        );
        let z = geo(r#"{"type":"Polygon","coordinates":[[[0,0,9],[1,0,9],[1,1,9]]]}"#).unwrap();
        assert_eq!(z[0].points, [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]);
        let e = geo(r#"{"type":"Polygon","coordinates":[[[0,0,9,9],[1,0],[1,1]]]}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("[x, y] or [x, y, z]"), "{e}");
        // A list of points a level too deep: items, not numbers (it said "point [[-2, -2],
        // [2, -2], [2, 2]] has 3 numbers").
        let e = yaml("- [[[-2, -2], [2, -2], [2, 2]]]\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("has 3 items; a point is [x, y] (a level of brackets too many?)"),
            "{e}"
        );
        // One polygon's points and a list of points mixed: named as such (it was "point
        // [[2, 2], [3, 2], [3, 3]] has 3 numbers").
        let e = yaml("- [-1, 2]\n- [[2, 2], [3, 2], [3, 3]]\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("item 2 is a list of points while item 1 is a point"),
            "{e}"
        );
        // A quoted number first is a coordinate that is not a number (it was "item 2 is a
        // point while item 1 is a list of points").
        let e = yaml("- [\"0\", 0]\n- [1, 0]\n- [1, 1]\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("coordinate \"0\" is not a number"), "{e}");
        let e = yaml("- [[2, 2], [3, 2], [3, 3]]\n- [2, 2]\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("item 2 is a point while item 1 is a list of points"),
            "{e}"
        );
        // A MultiPolygon member without rings was skipped in silence.
        let e = geo(r#"{"type":"MultiPolygon","coordinates":[[],[[[0,0],[1,0],[1,1]]]]}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("MultiPolygon member 1 has no ring"), "{e}");
    }

    #[test]
    fn geojson_and_yaml_shapes_parse() {
        let g: Value = serde_json::from_str(
            r#"{"type":"FeatureCollection","features":[
                {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,0]]]}},
                {"type":"Feature","properties":{"name":"desks"},"geometry":{"type":"MultiPolygon","coordinates":[[[[2,2],[3,2],[3,3]]],[[[5,5,0],[6,5,0],[6,6,0]]]]}}]}"#,
        )
        .unwrap();
        let p = geojson_polygons(&g).unwrap();
        let names: Vec<_> = p.iter().map(|p| p.name.as_deref()).collect();
        assert_eq!(names, [None, Some("desks"), Some("desks")]);
        let other: Value = serde_json::from_str(
            r#"{"type":"FeatureCollection","features":[
                {"type":"Feature","properties":{"name":42},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1]]]}},
                {"type":"Feature","properties":{"name":true},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1]]]}},
                {"type":"Feature","properties":{"name":["a"]},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1]]]}}]}"#,
        )
        .unwrap();
        let names: Vec<_> = geojson_polygons(&other)
            .unwrap()
            .into_iter()
            .map(|p| p.name)
            .collect();
        assert_eq!(names, [Some("42".into()), Some("true".into()), None]);
        assert_eq!(p.len(), 3);
        assert_eq!(p[2].points[1], [6.0, 5.0]);
        let holes: Value = serde_json::from_str(
            r#"{"type":"Polygon","coordinates":[[[0,0],[4,0],[4,4]],[[1,1],[2,1],[2,2]]]}"#,
        )
        .unwrap();
        assert!(geojson_polygons(&holes).is_err());
        let line: Value =
            serde_json::from_str(r#"{"type":"LineString","coordinates":[[0,0],[1,1]]}"#).unwrap();
        assert!(geojson_polygons(&line)
            .unwrap_err()
            .to_string()
            .contains("LineString"));
        let crs: Value = serde_json::from_str(
            r#"{"type":"FeatureCollection","crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::4326"}},"features":[]}"#,
        )
        .unwrap();
        let e = geojson_polygons(&crs).unwrap_err().to_string();
        assert!(
            e.contains("EPSG::4326") && e.contains("map coordinates"),
            "{e}"
        );
        // `"crs": null` names no CRS: read as usual.
        let none: Value = serde_json::from_str(
            r#"{"type":"Polygon","crs":null,"coordinates":[[[0,0],[1,0],[1,1]]]}"#,
        )
        .unwrap();
        assert_eq!(geojson_polygons(&none).unwrap().len(), 1);
        let one: Value = serde_saphyr::from_str("- [0, 0]\n- [1, 0]\n- [1, 1]\n").unwrap();
        assert_eq!(yaml_polygons(&one).unwrap().len(), 1);
        let two: Value = serde_saphyr::from_str(
            "polygons:\n  - [[0, 0], [1, 0], [1, 1]]\n  - [{x: 2, y: 2}, {x: 3, y: 2}, {x: 3, y: 3}]\n",
        )
        .unwrap();
        let p = yaml_polygons(&two).unwrap();
        assert_eq!(p.len(), 2);
        for extra in ["frame: odom\n", "polygon:\n  - [[0, 0], [1, 0], [1, 1]]\n"] {
            let v: Value = serde_saphyr::from_str(&format!(
                "polygons:\n  - [[0, 0], [1, 0], [1, 1]]\n{extra}"
            ))
            .unwrap();
            let e = yaml_polygons(&v).unwrap_err().to_string();
            let key = extra.split(':').next().unwrap();
            assert!(e.contains(&format!("unknown key `{key}`")), "{e}");
        }
        assert_eq!(p[1].points[2], [3.0, 3.0]);
    }

    #[test]
    fn specs_serialize_untagged() {
        let specs = vec![
            ZoneSpec::Rect([0.0, 0.0, 1.0, 1.0]),
            ZoneSpec::File("a.geojson".into()),
            ZoneSpec::Polygons(vec![Polygon {
                points: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
                name: None,
            }]),
        ];
        let j = serde_json::to_string(&specs).unwrap();
        assert_eq!(
            j,
            r#"[[0.0,0.0,1.0,1.0],"a.geojson",[[[0.0,0.0],[1.0,0.0],[1.0,1.0]]]]"#
        );
        let back: Vec<ZoneSpec> = serde_json::from_str(&j).unwrap();
        assert_eq!(back, specs);
        // A name from a zone file is not part of the spec: it comes from the file again.
        let named = Polygon {
            name: Some("rug".into()),
            ..Polygon::rect([0.0, 0.0, 1.0, 1.0])
        };
        assert_eq!(
            serde_json::to_string(&named).unwrap(),
            serde_json::to_string(&Polygon::rect([0.0, 0.0, 1.0, 1.0])).unwrap()
        );
        let f = MapFrame::new(10, 10, 0.1);
        assert!(ZoneSpec::Rect([1.0, 0.0, 0.0, 1.0]).load(&f, true).is_err());
    }
}
