//! `GET /api/modules/{id}/live`: a WebSocket that streams the signals the
//! app subscribed to (TMCL reads through the target) at the rate it asked
//! for, and the program's state when asked.

use crate::app::App;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path, State};
use axum::response::Response;
use serde_json::json;
use std::time::Duration;
use tmclsim_ide::live::{Subscription, sample};

/// Largest message (and frame) a client may send: a subscription of
/// [`MAX_SIGNALS`] signals takes a few KiB.
pub const MAX_MESSAGE: usize = 64 * 1024;
/// Most messages a client may send in one second; the socket of a client
/// that sends more is closed with a reason.
pub const MAX_MESSAGES_PER_SECOND: u32 = 50;

pub async fn live(ws: WebSocketUpgrade, State(app): State<App>, Path(id): Path<usize>) -> Response {
    ws.max_message_size(MAX_MESSAGE).max_frame_size(MAX_MESSAGE).on_upgrade(move |socket| stream(socket, app, id))
}

fn period(sub: &Subscription) -> Duration {
    Duration::from_secs_f64(1.0 / sub.hz())
}

async fn stream(mut socket: WebSocket, app: App, id: usize) {
    if id >= app.target.modules().len() {
        let _ = socket.send(Message::Text(json!({"error": "no such module"}).to_string().into())).await;
        return;
    }
    let mut sub = Subscription::default();
    let mut tick = tokio::time::interval(period(&sub));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let (mut second, mut messages) = (tokio::time::Instant::now(), 0u32);
    loop {
        tokio::select! {
            msg = socket.recv() => {
                let Some(Ok(msg)) = msg else { return };
                if second.elapsed() >= Duration::from_secs(1) {
                    (second, messages) = (tokio::time::Instant::now(), 0);
                }
                messages += 1;
                if messages > MAX_MESSAGES_PER_SECOND {
                    let reason = format!("more than {MAX_MESSAGES_PER_SECOND} messages in a second");
                    let _ = socket.send(Message::Text(json!({"error": reason}).to_string().into())).await;
                    let close = axum::extract::ws::CloseFrame { code: axum::extract::ws::close_code::POLICY, reason: reason.into() };
                    let _ = socket.send(Message::Close(Some(close))).await;
                    return;
                }
                let Message::Text(text) = msg else { continue };
                match Subscription::parse(&text) {
                    Ok(s) => {
                        tick = tokio::time::interval(period(&s));
                        tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
                        sub = s;
                    }
                    Err(e) => {
                        let _ = socket.send(Message::Text(json!({"error": e.to_string()}).to_string().into())).await;
                    }
                }
            }
            _ = tick.tick() => {
                // A module on a link in download mode would store the
                // reads as program words: the stream pauses.
                let Ok(used) = app.observable(id) else { continue };
                if sub.is_empty() {
                    continue;
                }
                let (a, s) = (app.clone(), sub.clone());
                let take = move || {
                    let _used = used;
                    sample(a.target.as_ref(), id, &s)
                };
                // Virtual modules answer in microseconds: no thread hand-off.
                let answer = if app.target.blocks() { tokio::task::spawn_blocking(take).await } else { Ok(take()) };
                let Ok(v) = answer else { return };
                let text = v.to_string();
                if socket.send(Message::Text(text.into())).await.is_err() {
                    return;
                }
            }
        }
    }
}
