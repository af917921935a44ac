//! Stage: spec loading. The one place that reads a scene description — from a file or a
//! string — applies command-line overrides (`--set radar.pulse_width_us=2`) and builds the
//! validated [`Scene`], with every error naming the file, line and column of the value at
//! fault (docs/architecture.md, "Spec → model").
//!
//! Syntax, type and choice errors come from the TOML deserializer with their position. Range
//! and consistency errors are found while building the model, which names the field by its
//! dotted path; [`locate`] then finds that field's value in the file through the parser's
//! spans (`toml::de::DeTable`, whose keys and values are `toml::Spanned`).

use super::SceneSpec;
use crate::error::{Error, Location, Result};
use crate::model::{ProcessingMode, Scene};
use crate::products::ppi::{Orientation, PpiSettings};
use std::path::{Path, PathBuf};
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// A scene description as read, with where it came from: what [`Scene`] is built from.
#[derive(Debug, Clone)]
pub struct LoadedSpec {
    spec: SceneSpec,
    origin: String,
    text: String,
    base_dir: PathBuf,
    overrides: Vec<String>,
    /// How overrides are named in errors: `--set` (the CLI) or the caller's word.
    overrides_label: String,
}

impl LoadedSpec {
    /// Reads a scene file; its mesh files are found relative to its directory.
    pub fn read(path: &Path) -> Result<LoadedSpec> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let base_dir = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        LoadedSpec::from_toml(&text, &path.display().to_string(), base_dir)
    }

    /// Parses scene TOML; `origin` names it in errors and mesh files are found relative to
    /// `base_dir`.
    pub fn from_toml(text: &str, origin: &str, base_dir: &Path) -> Result<LoadedSpec> {
        let spec: SceneSpec = toml::from_str(text).map_err(|e| Error::SceneSyntax {
            path: origin.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        Ok(LoadedSpec {
            spec,
            origin: origin.to_string(),
            text: text.to_string(),
            base_dir: base_dir.to_path_buf(),
            overrides: Vec::new(),
            overrides_label: "--set".into(),
        })
    }

    /// Applies overrides `FIELD=VALUE` in order, FIELD a dotted path (`radar.spokes`,
    /// `environment.sea_state`, `object[0].yaw_deg`, `environment.rain_cell[1].radius_m`) and
    /// VALUE a TOML value (`2`, `true`, `[0.0, 0.0, 8.0]`; a bare word is read as a string).
    pub fn with_overrides<S: AsRef<str>>(self, sets: &[S]) -> Result<LoadedSpec> {
        self.with_overrides_named("--set", sets)
    }

    /// [`LoadedSpec::with_overrides`], naming them `label` in errors instead of `--set` (the
    /// Python binding says `settings`).
    pub fn with_overrides_named<S: AsRef<str>>(
        mut self,
        label: &str,
        sets: &[S],
    ) -> Result<LoadedSpec> {
        self.overrides_label = label.to_string();
        if sets.is_empty() {
            return Ok(self);
        }
        let mut doc: toml::Table = toml::from_str(&self.text).map_err(|e| Error::SceneSyntax {
            path: self.origin.clone(),
            message: e.to_string().trim_end().to_string(),
        })?;
        for set in sets {
            let set = set.as_ref();
            let (field, value) = parse_override(set)?;
            assign(&mut doc, &field, value).map_err(|reason| Error::SceneSyntax {
                path: format!("{} {set}", self.overrides_label),
                message: reason,
            })?;
            self.overrides.push(field);
        }
        self.spec = toml::Value::Table(doc)
            .try_into()
            .map_err(|e: toml::de::Error| Error::SceneSyntax {
                path: format!(
                    "{} with {} {}",
                    self.origin,
                    self.overrides_label,
                    self.overrides.join(", ")
                ),
                message: e.to_string().trim_end().to_string(),
            })?;
        Ok(self)
    }

    /// The description.
    pub fn spec(&self) -> &SceneSpec {
        &self.spec
    }

    /// The description, to change before building (programmatic overrides).
    pub fn spec_mut(&mut self) -> &mut SceneSpec {
        &mut self.spec
    }

    /// Where the description came from (a file's path).
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// Directory that mesh files are found relative to.
    pub fn base_dir(&self) -> &Path {
        &self.base_dir
    }

    /// Validates the description into a scene; a field error carries the location of its
    /// value ([`Error::location`]).
    pub fn build(&self) -> Result<Scene> {
        let scene =
            Scene::from_spec_in(&self.spec, &self.base_dir).map_err(|e| self.locate_error(e))?;
        // `[display]` is the PPI product's, not the model's, but a file is valid or not as a
        // whole: every command refuses a bad display table.
        self.ppi_settings()?;
        Ok(scene)
    }

    /// Validates the `[display]` table into the PPI product's settings (errors located like
    /// [`LoadedSpec::build`]'s).
    pub fn ppi_settings(&self) -> Result<PpiSettings> {
        let settings =
            PpiSettings::from_spec(&self.spec.display).map_err(|e| self.locate_error(e))?;
        if settings.orientation != Orientation::NorthUp && self.spec.own_ship.is_none() {
            return Err(self.locate_error(crate::error::Error::invalid(
                crate::error::Problem::Conflict,
                "display.orientation",
                format!("{:?}", settings.orientation),
                "head-up and course-up turn the picture with the own ship: they need an [own_ship] table",
            )));
        }
        if settings.doppler_colour
            && self.spec.processing.mode.unwrap_or_default() != ProcessingMode::Pulse
        {
            return Err(self.locate_error(crate::error::Error::invalid(
                crate::error::Problem::Conflict,
                "display.doppler_colour",
                true,
                "colouring approaching echoes needs each cell's Doppler from its pulses: set [processing] mode = \"pulse\"",
            )));
        }
        Ok(settings)
    }

    /// Attaches where the field of a field error was given: `--set`, or the file's line and
    /// column.
    fn locate_error(&self, e: Error) -> Error {
        let Some(field) = e.field() else { return e };
        // An object's field is named by its name (`object "buoy".radius_m`) in errors and by
        // its index (`object[2].radius_m`) in overrides; an override of a whole array
        // (`radar.position_m`) covers its elements' errors.
        let by_index = field.strip_prefix("object \"").and_then(|rest| {
            let (name, tail) = rest.split_once("\".")?;
            let i = self
                .spec
                .objects
                .iter()
                .position(|o| o.name.as_deref() == Some(name))?;
            Some(format!("object[{i}].{tail}"))
        });
        let covers = |o: &String, f: &str| {
            f == o || f.starts_with(&format!("{o}.")) || f.starts_with(&format!("{o}["))
        };
        let overridden = self
            .overrides
            .iter()
            .any(|o| covers(o, field) || by_index.as_deref().is_some_and(|f| covers(o, f)));
        let location = if overridden {
            Location {
                origin: self.overrides_label.clone(),
                line_column: None,
            }
        } else {
            Location {
                origin: self.origin.clone(),
                line_column: locate(&self.text, field),
            }
        };
        e.at(location)
    }
}

/// Splits `FIELD=VALUE` and reads VALUE as TOML (a bare word as a string).
fn parse_override(set: &str) -> Result<(String, toml::Value)> {
    let bad = |why: &str| Error::SceneSyntax {
        path: format!("--set {set}"),
        message: format!("{why}; expected FIELD=VALUE, e.g. radar.pulse_width_us=2"),
    };
    let (field, value) = set.split_once('=').ok_or_else(|| bad("no `=`"))?;
    let field = field.trim();
    if field.is_empty() {
        return Err(bad("no field before `=`"));
    }
    let value = value.trim();
    let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    Ok((field.to_string(), parsed))
}

/// One step of a dotted path: a key, and an index when the key names an array of tables.
fn steps(field: &str) -> Vec<(String, Option<usize>)> {
    field
        .split('.')
        .map(|part| match part.split_once('[') {
            Some((key, rest)) => (
                key.to_string(),
                rest.trim_end_matches(']').parse::<usize>().ok(),
            ),
            None => (part.to_string(), None),
        })
        .collect()
}

/// Sets `field` (dotted path) in a TOML document, creating tables on the way.
/// Sets `field` (a dotted path as `--set` takes: `radar.spokes`, `object[0].yaw_deg`,
/// `radar.position_m[2]`) to `value` in a scene document, creating missing tables; an indexed
/// step must name an existing array element. The error says what is missing.
pub fn assign_field(
    doc: &mut toml::Table,
    field: &str,
    value: toml::Value,
) -> std::result::Result<(), String> {
    assign(doc, field, value)
}

fn assign(
    doc: &mut toml::Table,
    field: &str,
    value: toml::Value,
) -> std::result::Result<(), String> {
    let path = steps(field);
    let mut table = doc;
    for (n, (key, index)) in path.iter().enumerate() {
        let last = n + 1 == path.len();
        match index {
            None if last => {
                table.insert(key.clone(), value);
                return Ok(());
            }
            None => {
                let entry = table
                    .entry(key.clone())
                    .or_insert_with(|| toml::Value::Table(toml::Table::new()));
                table = entry
                    .as_table_mut()
                    .ok_or_else(|| format!("`{key}` is not a table"))?;
            }
            Some(i) => {
                let array = table
                    .get_mut(key)
                    .and_then(|v| v.as_array_mut())
                    .ok_or_else(|| format!("the scene has no `[[{key}]]` tables"))?;
                let count = array.len();
                let item = array.get_mut(*i).ok_or_else(|| {
                    format!(
                        "`{key}[{i}]`: the scene has {count} `[[{key}]]` table(s), numbered from 0"
                    )
                })?;
                if last {
                    *item = value;
                    return Ok(());
                }
                table = item
                    .as_table_mut()
                    .ok_or_else(|| format!("`{key}[{i}]` is not a table"))?;
            }
        }
    }
    Err("empty field".into())
}

/// 1-based line and column of the value of `field` in `text`: `radar.pulse_width_us`,
/// `environment.rain_cell[0].radius_m`, `object[2].name` or `object "buoy".radius_m` (the
/// object whose `name` is "buoy"). None when the field is not written in the text.
pub fn locate(text: &str, field: &str) -> Option<(usize, usize)> {
    let root = DeTable::parse(text).ok()?;
    let (mut value, rest): (Spanned<DeValue>, String) = if let Some(rest) =
        field.strip_prefix("object \"")
    {
        let (name, rest) = rest.split_once("\".")?;
        let objects = get(root.get_ref(), "object")?;
        let DeValue::Array(items) = objects.get_ref() else {
            return None;
        };
        let item = items.iter().find(|item| match item.get_ref() {
            DeValue::Table(t) => {
                get(t, "name").and_then(|n| n.get_ref().as_str().map(|s| s == name)) == Some(true)
            }
            _ => false,
        })?;
        (item.clone(), rest.to_string())
    } else {
        let span = root.span();
        (
            Spanned::new(span, DeValue::Table(root.into_inner())),
            field.to_string(),
        )
    };
    for (key, index) in steps(&rest) {
        let DeValue::Table(t) = value.get_ref() else {
            return None;
        };
        let next = get(t, &key)?;
        value = match index {
            None => next,
            Some(i) => match next.get_ref() {
                DeValue::Array(items) => items.get(i)?.clone(),
                _ => return None,
            },
        };
    }
    Some(line_column(text, value.span().start))
}

fn get<'i>(table: &DeTable<'i>, key: &str) -> Option<Spanned<DeValue<'i>>> {
    table
        .iter()
        .find(|(k, _)| k.get_ref().as_ref() == key)
        .map(|(_, v)| v.clone())
}

fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before
        .rfind('\n')
        .map_or(before.len(), |n| before.len() - n - 1)
        + 1;
    (line, column)
}
