//! The live stream's subscription and its samples: the signals the app
//! subscribed to, read as an observer reads them, and the program's state
//! when asked.

use crate::answers::{Read, read_all};
use crate::target::{Target, TargetError};
use serde::Deserialize;
use serde_json::{Value, json};

/// Most signals per subscription.
pub const MAX_SIGNALS: usize = 64;

/// What the live stream samples: the app's JSON.
#[derive(Deserialize, Default, Clone)]
pub struct Subscription {
    /// The values read in every sample.
    #[serde(default)]
    pub signals: Vec<Read>,
    /// Samples per second (1…100; 20 when not given).
    pub rate: Option<f64>,
    /// Whether every sample holds the program's state too.
    #[serde(default)]
    pub program: bool,
    /// Echoed as `sub` in every sample of this subscription, so that the
    /// app knows which signals a sample holds even while a new
    /// subscription is on its way.
    pub id: Option<u64>,
}

impl Subscription {
    /// A subscription from the app's JSON, or what is wrong with it.
    pub fn parse(text: &str) -> Result<Subscription, SubscriptionError> {
        let s: Subscription = serde_json::from_str(text).map_err(|e| SubscriptionError::Json(e.to_string()))?;
        if s.signals.len() > MAX_SIGNALS {
            return Err(SubscriptionError::TooManySignals);
        }
        Ok(s)
    }

    /// Samples per second, within 1…100.
    pub fn hz(&self) -> f64 {
        self.rate.filter(|r| r.is_finite()).unwrap_or(20.0).clamp(1.0, 100.0)
    }

    /// Whether there is anything to sample.
    pub fn is_empty(&self) -> bool {
        self.signals.is_empty() && !self.program
    }
}

/// What is wrong with a subscription.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SubscriptionError {
    /// Its JSON is wrong (the parser's message).
    Json(String),
    /// More than [`MAX_SIGNALS`] signals.
    TooManySignals,
}

impl std::fmt::Display for SubscriptionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SubscriptionError::Json(e) => write!(f, "subscription: {e}"),
            SubscriptionError::TooManySignals => write!(f, "at most {MAX_SIGNALS} signals"),
        }
    }
}

impl std::error::Error for SubscriptionError {}

impl From<SubscriptionError> for String {
    fn from(e: SubscriptionError) -> String {
        e.to_string()
    }
}

/// One sample: `{"t", "values", "program"?}`, or `{"error"}`.
pub fn sample(target: &dyn Target, id: usize, sub: &Subscription) -> Value {
    let take = || -> Result<Value, TargetError> {
        let (values, t) = read_all(target, id, &sub.signals)?;
        let mut out = json!({"t": t, "values": values});
        if let Some(id) = sub.id {
            out["sub"] = json!(id);
        }
        if sub.program {
            out["program"] = crate::program::state_of(target, id)?;
        }
        Ok(out)
    };
    take().unwrap_or_else(|e| json!({"error": e.to_string()}))
}
