//! Paper 003.
use super::{Measurements, PaperData, PaperOptions};
pub fn measure(_options: &PaperOptions, _data: &PaperData) -> Result<Measurements, String> {
    Err("not yet".into())
}
