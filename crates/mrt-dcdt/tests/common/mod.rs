//! Message types and Members shared by the integration tests.
#![allow(dead_code)]
#![allow(clippy::unwrap_used)]

use mrt_dcdt::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::{Arc, Mutex};
use std::time::Duration;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Count(pub u32);
impl Message for Count {
    const TYPE: MsgType = MsgType(10);
    const NAME: &'static str = "Count";
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Status(pub String);
impl Message for Status {
    const TYPE: MsgType = MsgType(11);
    const NAME: &'static str = "Status";
}

/// One received message, as a comparable record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Seen {
    pub at_ns: u64,
    pub receiver: String,
    pub from_agora: u32,
    pub from_member: u32,
    pub created_ns: u64,
    pub what: String,
}

pub type Log = Arc<Mutex<Vec<Seen>>>;

pub fn log() -> Log {
    Arc::new(Mutex::new(Vec::new()))
}

/// Publishes `Count(1..)` each cycle, and a `Status` every `status_every` cycles; terminates
/// after `limit` cycles (0 = never).
pub struct Producer {
    pub n: u32,
    pub limit: u32,
    pub status_every: u32,
}

impl Producer {
    pub fn new(limit: u32) -> Self {
        Self { n: 0, limit, status_every: 0 }
    }
}

impl Member for Producer {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.n += 1;
        ctx.publish(Count(self.n));
        if self.status_every > 0 && self.n % self.status_every == 0 {
            ctx.publish(Status(format!("at {}", self.n)));
        }
        if self.limit > 0 && self.n >= self.limit {
            ctx.terminate();
        }
        Ok(())
    }
}

/// Subscribes to the given types and logs every message it receives.
pub struct Recorder {
    pub name: String,
    pub subs: Vec<(MsgType, RequestType)>,
    pub log: Log,
}

impl Recorder {
    pub fn new(name: &str, subs: &[(MsgType, RequestType)], log: &Log) -> Self {
        Self { name: name.into(), subs: subs.to_vec(), log: log.clone() }
    }
}

pub fn describe(msg: &MsgRef) -> String {
    if let Ok(c) = msg.get::<Count>() {
        format!("Count({})", c.0)
    } else if let Ok(s) = msg.get::<Status>() {
        format!("Status({})", s.0)
    } else {
        format!("raw {:?} {:?}", msg.msg_type(), msg.bytes())
    }
}

impl Member for Recorder {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        for (t, r) in &self.subs {
            ctx.subscribe(*t, *r);
        }
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            let seen = Seen {
                at_ns: ctx.now().as_nanos(),
                receiver: self.name.clone(),
                from_agora: m.agora_id().0,
                from_member: m.member_id().0,
                created_ns: m.creation_time().as_nanos(),
                what: describe(&m),
            };
            self.log.lock().map_err(|_| "poisoned log")?.push(seen);
        }
        Ok(())
    }
}

pub fn whats(log: &Log, receiver: &str) -> Vec<String> {
    log.lock().unwrap().iter().filter(|s| s.receiver == receiver).map(|s| s.what.clone()).collect()
}

pub const MS: Duration = Duration::from_millis(1);
