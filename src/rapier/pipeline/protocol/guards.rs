//! What the run-time guards saw: one [`Violation`] per kind of guard and joint, holding the
//! worst value seen, when, and how many states violated (not the first: a run whose first
//! violation is 1 % over its limit may reach 6 times it later).

use super::ElementId;
use crate::error::sig4;
use serde::{Serialize, Serializer};

/// Which guard a [`Violation`] is of. What `worst` and `limit` measure depends on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum GuardKind {
    /// A contact deeper than its law's validity: `worst` the deepest penetration, `limit` the
    /// joint's `max_valid_penetration`, both in m.
    Penetration,
    /// A fixed step longer than friction's limit near zero slip: `worst` the largest ratio of
    /// the step to that limit, `limit` 1.
    Friction,
    /// Steps at the adaptive floor `min_dt`: `worst` the longest run of them in a row, `limit`
    /// the run that stalls (100,000); `count` all of them.
    Floor,
    /// Energy gained (recorded by the scene runner): `worst` the largest growth of the energy
    /// balance over the energy scale, `limit` the allowed growth; judged once over the run.
    Energy,
    /// A velocity motor off its speed (recorded by the scene runner): `worst` the largest
    /// relative speed error, `limit` the allowed one.
    MotorSpeed,
    /// A sub-cycled contact that needed more sub-steps in one world step than the sub-cycle
    /// takes ([`ContactIntegration::SubCycled`](crate::rapier::joint::ContactIntegration::SubCycled)):
    /// `worst` the sub-steps it took, `limit` that cap; the rest of the step went in one
    /// sub-step, unresolved.
    SubSteps,
    /// A guard of a participant of your own: its [`note`](Violation::note) is the whole
    /// message; `worst` and `limit` are its own.
    Other,
}

/// One kind of guard violated by one joint (or twin): the worst value, when, and how many
/// states violated it. Its `Display` states them in words.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Violation {
    /// The guard.
    pub kind: GuardKind,
    /// The name of the joint or element the guard concerns, if one (in the scene layer, the
    /// hinge's name in the scene; for a velocity motor, the motor's joint).
    pub joint: Option<String>,
    /// Its handle in its set ([`ElementHandle::id`](crate::rapier::pipeline::element_set::ElementHandle::id):
    /// the plain API's way to name it), if it has one.
    #[serde(skip)]
    pub handle: Option<ElementId>,
    /// The twin (`ideal`, `clearance`) for guards the scene runner records.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub twin: Option<String>,
    /// The worst value seen (see [`GuardKind`] for what it measures).
    pub worst: f64,
    /// The limit it passed.
    pub limit: f64,
    /// Simulated time of the worst value, s.
    pub t_s: f64,
    /// Simulated time of the first violation, s.
    pub first_t_s: f64,
    /// States (accepted steps) that violated the guard.
    pub count: u64,
    /// Extra words (the step in use, the floor...); for [`GuardKind::MotorSpeed`] the advice,
    /// in place of the default that names the plain API's parameters; for [`GuardKind::Other`]
    /// the whole message.
    #[serde(skip)]
    pub(crate) note: String,
    /// The unit of `worst` and `limit` where they are absolute rather than the kind's usual
    /// measure: a velocity motor whose target is 0 reports its miss in rad/s or m/s (relative to
    /// a zero target it has no meaning).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unit: Option<&'static str>,
}

impl Violation {
    /// A violation of `kind` by one state at time `t_s`: `value` against `limit`.
    pub fn new(kind: GuardKind, value: f64, limit: f64, t_s: f64) -> Self {
        Violation {
            kind,
            joint: None,
            handle: None,
            twin: None,
            worst: value,
            limit,
            t_s,
            first_t_s: t_s,
            count: 1,
            note: String::new(),
            unit: None,
        }
    }

    /// Names the joint or element the violation concerns (and its handle in its set).
    pub fn joint(mut self, name: &str, handle: Option<ElementId>) -> Self {
        self.joint = Some(name.to_string());
        self.handle = handle;
        self
    }

    /// Names the twin.
    pub(crate) fn twin(mut self, name: &str) -> Self {
        self.twin = Some(name.to_string());
        self
    }

    /// Adds words to the message.
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.note = note.into();
        self
    }

    fn same_subject(&self, other: &Violation) -> bool {
        self.kind == other.kind
            && self.joint == other.joint
            && self.handle == other.handle
            && self.twin == other.twin
            && (self.kind != GuardKind::Other || self.note == other.note)
    }

    /// `worst` over `limit` (0 without a limit).
    pub(crate) fn ratio(&self) -> f64 {
        if self.limit > 0.0 {
            self.worst / self.limit
        } else {
            0.0
        }
    }
}

/// The violation in words: the worst value against its limit, when, where, how often.
impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.in_words())
    }
}

impl Violation {
    /// The violation in words ([`Display`](std::fmt::Display)).
    fn in_words(&self) -> String {
        let joint = self.joint.as_deref().unwrap_or("?");
        let twin = self.twin.as_deref().unwrap_or("?");
        let states = |n: u64| {
            if n == 1 {
                format!("1 state, at t = {} s", sig4(self.first_t_s))
            } else {
                format!("{n} states, the first at t = {} s", sig4(self.first_t_s))
            }
        };
        match self.kind {
            GuardKind::Penetration => format!(
                "joint `{joint}` penetrated beyond its law's validity: worst {} um against {} um \
                 ({} times the limit) at t = {} s; {} beyond the limit",
                sig4(self.worst * 1e6),
                sig4(self.limit * 1e6),
                sig4(self.ratio()),
                sig4(self.t_s),
                states(self.count)
            ),
            GuardKind::Friction => format!(
                "joint `{joint}`: the fixed step is longer than friction's limit near zero slip, \
                 worst {} times it at t = {} s ({}; {}): stiction is a numerical chatter there; \
                 adaptive steps resolve it",
                sig4(self.worst),
                sig4(self.t_s),
                self.note,
                states(self.count)
            ),
            GuardKind::Floor => format!(
                "{} steps at the floor {}: the longest run {} in a row, ending at t = {} s (the \
                 first at t = {} s): contacts resolved no better than the floor allows",
                self.count,
                self.note,
                sig4(self.worst),
                sig4(self.t_s),
                sig4(self.first_t_s)
            ),
            GuardKind::Energy => format!(
                "the {twin} twin gained energy: {} of its energy scale (limit {}), the most at \
                 t = {} s{}",
                sig4(self.worst),
                sig4(self.limit),
                sig4(self.t_s),
                self.note
            ),
            GuardKind::MotorSpeed => {
                let miss = match self.unit {
                    Some(unit) => format!(
                        "{} {unit} (its target is 0; limit {} {unit})",
                        sig4(self.worst),
                        sig4(self.limit)
                    ),
                    None => format!(
                        "{} of its target (limit {})",
                        sig4(self.worst),
                        sig4(self.limit)
                    ),
                };
                let advice = if self.note.is_empty() {
                    "; raise its damping `factor`, shorten the steps (`StepControl`'s `max_dt`) or, \
                     in a chain of ideal joints, raise the world's \
                     `integration_parameters.num_internal_pgs_iterations`"
                } else {
                    &self.note
                };
                format!(
                    "the {twin} twin's velocity motor `{joint}` missed its speed by {miss} at \
                     worst, at t = {} s ({}): its torque and the reactions assume it holds \
                     it{advice}",
                    sig4(self.t_s),
                    states(self.count)
                )
            }
            GuardKind::SubSteps => format!(
                "joint `{joint}`: its sub-cycled contact reached {} sub-steps in one world step \
                 at t = {} s ({}), the rest of the step unresolved: shorten the world's step or \
                 loosen the tolerance",
                self.worst,
                sig4(self.t_s),
                states(self.count)
            ),
            GuardKind::Other => self.note.clone(),
        }
    }
}

/// What the guards saw over all steps so far.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GuardReport {
    /// Steps rejected and retried shorter.
    pub rejected_steps: u64,
    /// Deepest penetration over its joint's validity limit seen, as a ratio (0 without contact;
    /// above 1 is a violation).
    pub worst_penetration_ratio: f64,
    /// Steps taken at the floor `min_dt`.
    pub floor_steps: u64,
    /// One entry per kind of guard and joint (or twin), in the order first seen: the worst
    /// value, when, and how many states violated it. Empty when the run stayed valid.
    pub violations: Vec<Violation>,
}

impl GuardReport {
    /// No violation recorded.
    pub fn is_clean(&self) -> bool {
        self.violations.is_empty()
    }

    /// Merges one violating state (or a summary of several: its `count`) into the entry of its
    /// kind and joint: counts it, keeps the worst value and its time, and the first time.
    pub fn record(&mut self, v: Violation) {
        match self.violations.iter_mut().find(|e| e.same_subject(&v)) {
            Some(e) => {
                e.count += v.count;
                e.first_t_s = e.first_t_s.min(v.first_t_s);
                if v.worst > e.worst {
                    e.worst = v.worst;
                    e.t_s = v.t_s;
                    e.limit = v.limit;
                    e.note = v.note;
                    e.unit = v.unit;
                }
            }
            None => self.violations.push(v),
        }
    }

    /// The worst violation of `kind` over all joints and twins (largest ratio to its limit).
    pub fn worst(&self, kind: GuardKind) -> Option<&Violation> {
        self.violations
            .iter()
            .filter(|v| v.kind == kind)
            .max_by(|a, b| a.ratio().total_cmp(&b.ratio()))
    }

    /// Every violation in words, each stating its worst value, when, where and how often.
    pub fn messages(&self) -> Vec<String> {
        self.violations.iter().map(Violation::to_string).collect()
    }
}

impl Serialize for GuardReport {
    /// The counters, the violations (kind, joint, worst, limit, time, count) and the same in
    /// words (`messages`).
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct View<'a> {
            rejected_steps: u64,
            worst_penetration_ratio: f64,
            floor_steps: u64,
            violations: Vec<ViolationView<'a>>,
            messages: Vec<String>,
        }
        #[derive(Serialize)]
        struct ViolationView<'a> {
            kind: GuardKind,
            #[serde(skip_serializing_if = "Option::is_none")]
            joint: Option<&'a str>,
            #[serde(skip_serializing_if = "Option::is_none")]
            twin: Option<&'a str>,
            worst: f64,
            limit: f64,
            t_s: f64,
            first_t_s: f64,
            count: u64,
        }
        View {
            rejected_steps: self.rejected_steps,
            worst_penetration_ratio: self.worst_penetration_ratio,
            floor_steps: self.floor_steps,
            violations: self
                .violations
                .iter()
                .map(|v| ViolationView {
                    kind: v.kind,
                    joint: v.joint.as_deref().filter(|_| v.kind != GuardKind::Other),
                    twin: v.twin.as_deref(),
                    worst: v.worst,
                    limit: v.limit,
                    t_s: v.t_s,
                    first_t_s: v.first_t_s,
                    count: v.count,
                })
                .collect(),
            messages: self.messages(),
        }
        .serialize(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pen(depth: f64, t: f64) -> Violation {
        Violation::new(GuardKind::Penetration, depth, 50e-6, t)
            .joint("pin", Some(ElementId::from_raw_parts(0, 0)))
    }

    #[test]
    fn keeps_the_worst_the_first_time_and_the_count() {
        let mut g = GuardReport::default();
        g.record(pen(50.5e-6, 0.001));
        g.record(pen(325e-6, 0.004));
        g.record(pen(60e-6, 0.009));
        assert_eq!(g.violations.len(), 1);
        let v = &g.violations[0];
        assert_eq!(
            (v.worst, v.t_s, v.first_t_s, v.count),
            (325e-6, 0.004, 0.001, 3)
        );
        let m = v.to_string();
        assert!(
            m.contains("325 um") && m.contains("6.5 times") && m.contains("3 states"),
            "{m}"
        );
        assert!(
            m.contains("t = 0.004 s") && m.contains("first at t = 0.001 s"),
            "{m}"
        );
    }

    #[test]
    fn joints_and_kinds_are_kept_apart() {
        let mut g = GuardReport::default();
        g.record(pen(60e-6, 0.001));
        g.record(
            Violation::new(GuardKind::Penetration, 70e-6, 50e-6, 0.002)
                .joint("other", Some(ElementId::from_raw_parts(1, 0))),
        );
        g.record(Violation::new(GuardKind::Energy, 0.05, 0.01, 0.3).twin("ideal"));
        let mine = || {
            Violation::new(GuardKind::Other, 2.0, 1.0, 0.5)
                .joint("mine", None)
                .note("my own guard")
        };
        g.record(mine());
        g.record(mine());
        assert_eq!(g.violations.len(), 4);
        assert_eq!(
            g.worst(GuardKind::Penetration).unwrap().joint.as_deref(),
            Some("other")
        );
        assert_eq!(g.violations[3].count, 2);
        assert_eq!(g.messages()[3], "my own guard");
        let json = serde_json::to_value(&g).unwrap();
        assert_eq!(json["violations"][1]["joint"], "other");
        assert_eq!(json["violations"][1]["worst"], 70e-6);
        assert_eq!(json["violations"][2]["twin"], "ideal");
        assert!(json["violations"][3].get("joint").is_none());
        assert_eq!(json["messages"][3], "my own guard");
    }
}
