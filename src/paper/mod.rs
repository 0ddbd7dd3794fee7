//! The paper itself: its numerical claims beside seethru's values, its figures, and the
//! reproduction of its §5 as a report.

pub mod claims;
pub mod figures;
pub mod report;
pub mod reproduce;
