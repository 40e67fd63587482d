//! The live web monitor (feature `serve`): one page with no build step, served from the
//! binary, that draws a [`Timeline`](crate::Timeline) while it grows (`mrt sim --serve`) or
//! after it was read whole (`mrt replay FILE --serve`). See `docs/monitor.md`.
//!
//! Routes:
//! - `GET /`: the page (`web/index.html`, compiled in);
//! - `GET /meta`: `{"title", "field", "first", "end", "finished"}`;
//! - `GET /frame/{i}` (`i` a frame index or `latest`): `{"first", "end", "finished", "index",
//!   "frame"}`, the frame a [`Frame`](crate::view::Frame) or `null`;
//! - `GET /image/{team}/{k}/{i}`: robot `team/k`'s camera image (JPEG) last taken at or
//!   before frame `i`, when the recording has images (`mrt sim --images`);
//! - `GET /seen/{team}/{k}/{i}`: what robot `team/k`'s vision found in that same image, where
//!   in it (a [`SeenImage`](crate::view::SeenImage): time, image size, boxes in pixels), when
//!   its percepts said (ISocRob-2000 report §3.2.7);
//! - `GET /hfsm/{team}/{k}/{i}`: the shape of robot `team/k`'s HFSM in force at frame `i` (an
//!   `HfsmStructure`: machines, states, transitions), when its behavior Member told it
//!   (ThinkingCap/TeamChaos report §4.1, §5.1);
//! - `GET /ws`: a WebSocket; each text message `{"frame": i}` (or `"latest"`) is answered
//!   with what `/frame/{i}` answers. The page plays, pauses, steps and scrubs by asking.

use crate::view::SharedTimeline;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use std::net::SocketAddr;
use std::sync::Arc;

/// The page, compiled into the binary.
const PAGE: &str = include_str!("../web/index.html");

/// What can go wrong starting the monitor.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The address could not be bound (in use, not this machine's).
    #[error("cannot listen on {addr}: {source}")]
    Bind {
        /// The address.
        addr: SocketAddr,
        /// Why.
        source: std::io::Error,
    },
    /// The server's runtime or thread could not start.
    #[error("cannot start the monitor's server: {0}")]
    Start(std::io::Error),
}

/// A web monitor serving on its own thread until the process ends.
#[derive(Debug)]
pub struct Server {
    addr: SocketAddr,
}

#[derive(Clone)]
struct Shared {
    timeline: SharedTimeline,
    title: Arc<str>,
}

impl Server {
    /// Listens on `addr` (port 0: any free port) and serves `timeline` under the page title
    /// `title`, on a thread of its own. Returns once the address is bound.
    pub fn start(
        addr: SocketAddr,
        timeline: SharedTimeline,
        title: &str,
    ) -> Result<Server, ServeError> {
        let listener = std::net::TcpListener::bind(addr)
            .map_err(|source| ServeError::Bind { addr, source })?;
        let bound = listener.local_addr().map_err(|source| ServeError::Bind { addr, source })?;
        listener.set_nonblocking(true).map_err(ServeError::Start)?;
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .map_err(ServeError::Start)?;
        let shared = Shared { timeline, title: title.into() };
        let app = Router::new()
            .route("/", get(page))
            .route("/meta", get(meta))
            .route("/frame/{index}", get(frame))
            .route("/image/{team}/{k}/{index}", get(camera))
            .route("/seen/{team}/{k}/{index}", get(seen))
            .route("/hfsm/{team}/{k}/{index}", get(hfsm))
            .route("/ws", get(socket))
            .with_state(shared);
        std::thread::Builder::new()
            .name("mrt-monitor-http".into())
            .spawn(move || {
                runtime.block_on(async move {
                    match tokio::net::TcpListener::from_std(listener) {
                        Ok(l) => {
                            if let Err(e) = axum::serve(l, app).await {
                                tracing::error!("the monitor's server stopped: {e}");
                            }
                        }
                        Err(e) => tracing::error!("the monitor's listener: {e}"),
                    }
                });
            })
            .map_err(ServeError::Start)?;
        Ok(Server { addr: bound })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address, `http://ADDR/`.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }
}

async fn page() -> Response {
    ([(header::CONTENT_TYPE, "text/html; charset=utf-8")], PAGE).into_response()
}

fn json(body: String) -> Response {
    ([(header::CONTENT_TYPE, "application/json")], body).into_response()
}

async fn meta(State(s): State<Shared>) -> Response {
    let Ok(t) = s.timeline.lock() else {
        return (StatusCode::INTERNAL_SERVER_ERROR, "the timeline's lock is poisoned")
            .into_response();
    };
    let body = serde_json::json!({
        "title": &*s.title,
        "field": t.field(),
        "first": t.first(),
        "end": t.end(),
        "finished": t.is_finished(),
    });
    json(body.to_string())
}

/// `{"first", "end", "finished", "index", "frame"}` for `request`: a frame index, or
/// `latest`; an index outside the kept frames is clamped into them.
fn envelope(s: &Shared, request: &str) -> String {
    let Ok(t) = s.timeline.lock() else {
        return r#"{"error":"the timeline's lock is poisoned"}"#.to_string();
    };
    let (first, end) = (t.first(), t.end());
    let last = end.saturating_sub(1).max(first);
    let index = match request.trim() {
        "latest" => last,
        i => match i.parse::<i64>() {
            Ok(i) => usize::try_from(i).unwrap_or(0).clamp(first, last),
            Err(_) => {
                return serde_json::json!({ "error": format!("not a frame index: {request:?}") })
                    .to_string()
            }
        },
    };
    let frame = t.frame(index);
    format!(
        r#"{{"first":{first},"end":{end},"finished":{},"index":{index},"frame":{}}}"#,
        t.is_finished(),
        frame.as_deref().unwrap_or("null")
    )
}

async fn frame(State(s): State<Shared>, Path(index): Path<String>) -> Response {
    json(envelope(&s, &index))
}

/// What the timeline holds of robot `team/k` by frame `index`, as `answer` makes it into a
/// response; 404 with `missing` when it holds nothing.
fn of_robot(
    s: &Shared,
    (team, k, index): (String, String, usize),
    missing: &'static str,
    answer: impl FnOnce(&crate::Timeline, &str, usize) -> Option<Response>,
) -> Response {
    let Ok(t) = s.timeline.lock() else {
        return (StatusCode::INTERNAL_SERVER_ERROR, "the timeline's lock is poisoned")
            .into_response();
    };
    answer(&t, &format!("{team}/{k}"), index)
        .unwrap_or_else(|| (StatusCode::NOT_FOUND, missing).into_response())
}

async fn camera(State(s): State<Shared>, Path(at): Path<(String, String, usize)>) -> Response {
    of_robot(&s, at, "no camera image of that robot by that frame", |t, robot, i| {
        let jpeg = t.image(robot, i)?;
        let body = axum::body::Bytes::from_owner(jpeg);
        Some(([(header::CONTENT_TYPE, "image/jpeg")], body).into_response())
    })
}

async fn seen(State(s): State<Shared>, Path(at): Path<(String, String, usize)>) -> Response {
    of_robot(&s, at, "no detections for that robot's image by that frame", |t, robot, i| {
        t.image_seen(robot, i).map(|seen| json(seen.to_string()))
    })
}

async fn hfsm(State(s): State<Shared>, Path(at): Path<(String, String, usize)>) -> Response {
    of_robot(&s, at, "no HFSM told by that robot by that frame", |t, robot, i| {
        t.hfsm(robot, i).map(|shape| json(shape.to_string()))
    })
}

async fn socket(State(s): State<Shared>, ws: WebSocketUpgrade) -> Response {
    ws.on_upgrade(move |socket| answer(socket, s))
}

/// Answers each `{"frame": i}` with its envelope until the page goes away; anything else is
/// answered with an error and the socket stays open.
async fn answer(mut socket: WebSocket, s: Shared) {
    while let Some(Ok(message)) = socket.recv().await {
        let reply = match message {
            Message::Text(text) => match serde_json::from_str::<serde_json::Value>(text.as_str()) {
                Ok(v) => match &v["frame"] {
                    serde_json::Value::Number(n) => envelope(&s, &n.to_string()),
                    serde_json::Value::String(w) => envelope(&s, w),
                    _ => r#"{"error":"ask for {\"frame\": index or \"latest\"}"}"#.to_string(),
                },
                Err(e) => serde_json::json!({ "error": e.to_string() }).to_string(),
            },
            Message::Close(_) => break,
            _ => continue,
        };
        if socket.send(Message::Text(reply.into())).await.is_err() {
            break;
        }
    }
}
