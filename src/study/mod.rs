//! Parameter sweeps, the paper's studies, metrics and plots (issue 3). Placeholder until built.
