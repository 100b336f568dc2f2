//! Each study's `report.md`: setup, metrics tables, figures, and for each of the paper's
//! conclusions (MODEL.md §5) what our numbers show. The verdicts are computed from the metrics
//! with the criteria stated in the report; nothing is tuned to agree with the paper.
//!
//! - [`verdict`]: verdicts, the criteria behind them, and the parts of a finding.
//! - [`paper`]: the paper's four conclusions, each judged against a study's cases.
//! - [`setup`]: the settings and names a report states.
//! - [`tables`]: number formatting and the key tables of a study.
//! - [`timeline`]: contact onsets per window of simulated time.
//! - [`markdown`]: the report files, a study's and the summary of `study all`.

pub mod markdown;
pub mod paper;
pub mod setup;
pub mod tables;
pub mod timeline;
pub mod verdict;

pub use markdown::{IndexEntry, index_report, md_cell, study_report};
pub use paper::{PAPER, conclusions};
pub use setup::Setup;
pub use tables::{key_tables, num};
pub use timeline::Timeline;
pub use verdict::{
    ANGLE_SLIGHT, Conclusion, EQUAL_TOL, FORCE_STRONG, MIN_IMPACTS, RATE_VISIBLE, Verdict,
};
