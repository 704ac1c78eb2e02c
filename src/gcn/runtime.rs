//! TEMPORARY stub (replaced by the ort runtime from branch gcn-ort).
use super::features::GraphInputs;
use crate::error::{Error, Result};

/// A loaded model.
pub struct Model {}

impl Model {
    /// Loads a model from ONNX bytes.
    pub fn from_bytes(_bytes: &[u8]) -> Result<Model> {
        Err(Error::InvalidArgument("model: stub".into()))
    }
    /// Loads a model file.
    pub fn from_file(_p: &std::path::Path) -> Result<Model> {
        Err(Error::InvalidArgument("model: stub".into()))
    }
    /// Predicts.
    pub fn predict(&self, _g: &GraphInputs) -> Result<Vec<[f32; 2]>> {
        Err(Error::InvalidArgument("model: stub".into()))
    }
}
