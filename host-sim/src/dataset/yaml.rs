//! The few `sensor.yaml` keys the layout names, read with `yaml-rust2`.

use super::DatasetError;
use std::path::Path;
use yaml_rust2::{Yaml, YamlLoader};

/// A parsed `sensor.yaml`.
#[derive(Debug, Clone)]
pub struct SensorYaml {
    doc: Yaml,
    path: std::path::PathBuf,
}

impl SensorYaml {
    /// Reads and parses `path`.
    pub fn read(path: &Path) -> Result<Self, DatasetError> {
        let text = std::fs::read_to_string(path).map_err(|e| DatasetError::file(path, e))?;
        let mut docs = YamlLoader::load_from_str(&text)
            .map_err(|e| DatasetError::at(path, e.marker().line() as u64 + 1, e.to_string()))?;
        let doc = if docs.is_empty() {
            Yaml::Null
        } else {
            docs.swap_remove(0)
        };
        Ok(Self {
            doc,
            path: path.to_path_buf(),
        })
    }

    fn number(y: &Yaml) -> Option<f64> {
        match y {
            Yaml::Real(s) => s.parse().ok(),
            Yaml::Integer(i) => Some(*i as f64),
            _ => None,
        }
    }

    /// A required number.
    pub fn f64(&self, key: &str) -> Result<f64, DatasetError> {
        Self::number(&self.doc[key]).ok_or_else(|| {
            DatasetError::file(&self.path, format!("key '{key}' missing or not a number"))
        })
    }

    /// Whether `key` is given (a value other than null).
    #[must_use]
    pub fn has(&self, key: &str) -> bool {
        !matches!(&self.doc[key], Yaml::BadValue | Yaml::Null)
    }

    /// An optional number.
    pub fn f64_or(&self, key: &str, default: f64) -> Result<f64, DatasetError> {
        match &self.doc[key] {
            Yaml::BadValue | Yaml::Null => Ok(default),
            _ => self.f64(key),
        }
    }

    /// A list of numbers, either `key: [..]` or EuRoC's `key: {rows, cols, data: [..]}`.
    pub fn list(&self, key: &str, len: usize) -> Result<Vec<f64>, DatasetError> {
        let node = &self.doc[key];
        let arr = match node {
            Yaml::Array(a) => a,
            Yaml::Hash(_) => match &node["data"] {
                Yaml::Array(a) => a,
                _ => {
                    return Err(DatasetError::file(
                        &self.path,
                        format!("key '{key}' has no data list"),
                    ))
                }
            },
            _ => {
                return Err(DatasetError::file(
                    &self.path,
                    format!("key '{key}' missing or not a list"),
                ))
            }
        };
        let v: Option<Vec<f64>> = arr.iter().map(Self::number).collect();
        match v {
            Some(v) if v.len() == len => Ok(v),
            Some(v) => Err(DatasetError::file(
                &self.path,
                format!("key '{key}' has {} numbers, expected {len}", v.len()),
            )),
            None => Err(DatasetError::file(
                &self.path,
                format!("key '{key}' holds a non-number"),
            )),
        }
    }
}
