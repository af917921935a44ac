//! The HTTP side of the live radar (docs/live.md, "The radar API"): the page at `/`, the
//! mayara v1 radar API — `/v1/api/radars`, the spoke stream and the control stream as
//! WebSockets, `/v1/api/RadarMessage.proto` — a REST control setter, the scenario (clock,
//! pause, resume, restart, speed) and the truth at this moment. Every client reads the
//! streams through its own cursor into a bounded backlog: one that falls a backlog behind,
//! or takes longer than [`CLIENT_SEND_TIMEOUT`] over a message, is dropped, and the radar
//! never waits for anyone.

use crate::controls::ControlValue;
use crate::live::{Live, CLIENT_SEND_TIMEOUT};
use crate::radar::RadarSource;
use axum::extract::ws::rejection::WebSocketUpgradeRejection;
use axum::extract::ws::{CloseFrame, Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, put};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::{json, Value};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use tokio::sync::broadcast::error::RecvError;
use xbandsim::model::motion::{course_of, KNOT_M_PER_S};

/// The page, shipped in the binary.
const PAGE: &str = include_str!("page.html");

/// What the handlers share.
pub struct App {
    /// The live state.
    pub live: Arc<Live>,
    /// The scene's radar (None in a replay: no truth to tell).
    pub source: Option<Arc<RadarSource>>,
    /// The radar's description without its stream addresses.
    pub description: Value,
}

type Shared = Arc<App>;

/// An error response: status and a one-line message, as JSON `{"error": ...}`.
fn refuse(status: StatusCode, message: impl Into<String>) -> Response {
    (status, Json(json!({"error": message.into()}))).into_response()
}

/// The router.
pub fn router(app: Shared) -> Router {
    Router::new()
        .route("/", get(page))
        .route("/v1/api/radars", get(radars))
        .route("/v1/api/RadarMessage.proto", get(proto))
        .route("/v1/api/stream/{id}", get(stream))
        .route("/v1/api/control/{id}", get(control_stream))
        .route("/v1/api/radars/{id}/controls/{control}", put(set_control))
        .route("/api/scenario", get(scenario).post(change_scenario))
        .route("/api/truth", get(truth))
        .method_not_allowed_fallback(|| async {
            refuse(
                StatusCode::METHOD_NOT_ALLOWED,
                "this address does not take that method (docs/live.md, \"The radar API\")",
            )
        })
        .fallback(|| async {
            refuse(
                StatusCode::NOT_FOUND,
                "no such page: see / for the PPI, /v1/api/radars for the radar, /api/scenario and /api/truth (docs/live.md)",
            )
        })
        .with_state(app)
}

async fn page() -> Response {
    ([(header::CONTENT_TYPE, "text/html; charset=utf-8")], PAGE).into_response()
}

async fn proto() -> Response {
    (
        [(header::CONTENT_TYPE, "text/plain; charset=utf-8")],
        crate::proto::PROTO,
    )
        .into_response()
}

async fn radars(State(app): State<Shared>, headers: HeaderMap) -> Response {
    let host = headers
        .get(header::HOST)
        .and_then(|h| h.to_str().ok())
        .unwrap_or("127.0.0.1");
    let mut d = app.description.clone();
    d["streamUrl"] = json!(format!("ws://{host}/v1/api/stream/1"));
    d["controlUrl"] = json!(format!("ws://{host}/v1/api/control/1"));
    Json(json!({ "1": d })).into_response()
}

fn known_radar(id: &str) -> Result<(), Response> {
    if id == "1" {
        Ok(())
    } else {
        Err(refuse(
            StatusCode::NOT_FOUND,
            format!("no radar {id:?}: this server has one radar, \"1\""),
        ))
    }
}

/// Client messages are small JSON control values: anything over this is refused.
const MAX_CLIENT_MESSAGE_BYTES: usize = 64 * 1024;

/// The upgrade of a request for radar `id`'s stream, or the 4xx saying why not (no such
/// radar, or not a WebSocket request).
fn upgrade(
    id: &str,
    ws: Result<WebSocketUpgrade, WebSocketUpgradeRejection>,
) -> Result<WebSocketUpgrade, Response> {
    known_radar(id)?;
    ws.map(|w| {
        w.max_message_size(MAX_CLIENT_MESSAGE_BYTES)
            .max_frame_size(MAX_CLIENT_MESSAGE_BYTES)
    })
    .map_err(|e| {
        refuse(
            StatusCode::BAD_REQUEST,
            format!(
                "this address is a WebSocket: connect with a WebSocket client ({})",
                e.body_text()
            ),
        )
    })
}

async fn stream(
    State(app): State<Shared>,
    Path(id): Path<String>,
    ws: Result<WebSocketUpgrade, WebSocketUpgradeRejection>,
) -> Response {
    match upgrade(&id, ws) {
        Ok(ws) => ws.on_upgrade(move |socket| spoke_client(socket, app)),
        Err(r) => r,
    }
}

async fn spoke_client(mut socket: WebSocket, app: Shared) {
    let live = &app.live;
    let mut rx = live.spokes.subscribe();
    let mut ended = live.ended_signal();
    live.spoke_clients.fetch_add(1, Ordering::SeqCst);
    loop {
        tokio::select! {
            _ = ended.changed() => {
                // What the radar sent before it stopped still goes out.
                while let Ok(bytes) = rx.try_recv() {
                    let sent = tokio::time::timeout(CLIENT_SEND_TIMEOUT, socket.send(Message::Binary(bytes))).await;
                    if !matches!(sent, Ok(Ok(()))) {
                        break;
                    }
                }
                let _ = tokio::time::timeout(CLIENT_SEND_TIMEOUT, socket.send(Message::Close(None))).await;
                break;
            }
            m = rx.recv() => match m {
                Ok(bytes) => {
                    let sent = tokio::time::timeout(CLIENT_SEND_TIMEOUT, socket.send(Message::Binary(bytes))).await;
                    if !matches!(sent, Ok(Ok(()))) {
                        live.client_dropped();
                        break;
                    }
                }
                Err(RecvError::Lagged(n)) => {
                    live.client_dropped();
                    let reason = format!("dropped: {n} messages behind the radar");
                    let _ = tokio::time::timeout(
                        CLIENT_SEND_TIMEOUT,
                        socket.send(Message::Close(Some(CloseFrame { code: 1008, reason: reason.into() }))),
                    ).await;
                    break;
                }
                Err(RecvError::Closed) => break,
            },
            incoming = socket.recv() => match incoming {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => break,
                Some(Ok(_)) => {}
            },
        }
    }
    live.spoke_clients.fetch_sub(1, Ordering::SeqCst);
}

async fn control_stream(
    State(app): State<Shared>,
    Path(id): Path<String>,
    ws: Result<WebSocketUpgrade, WebSocketUpgradeRejection>,
) -> Response {
    match upgrade(&id, ws) {
        Ok(ws) => ws.on_upgrade(move |socket| control_client(socket, app)),
        Err(r) => r,
    }
}

async fn control_client(mut socket: WebSocket, app: Shared) {
    let live = &app.live;
    let mut rx = live.control_values.subscribe();
    let mut stop = live.stop_signal();
    for v in live.controls().values() {
        let text = serde_json::to_string(&v).expect("a control value serialises");
        if socket.send(Message::Text(text.into())).await.is_err() {
            return;
        }
    }
    loop {
        tokio::select! {
            _ = stop.changed() => break,
            m = rx.recv() => match m {
                Ok(text) => {
                    let sent = tokio::time::timeout(CLIENT_SEND_TIMEOUT, socket.send(Message::Text(text.into()))).await;
                    if !matches!(sent, Ok(Ok(()))) { break; }
                }
                Err(RecvError::Lagged(_)) => continue,
                Err(RecvError::Closed) => break,
            },
            incoming = socket.recv() => match incoming {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => break,
                Some(Ok(Message::Text(text))) => {
                    let reply = match serde_json::from_str::<ControlValue>(&text) {
                        Ok(v) => match live.set_control(&v) {
                            Ok(_) => None,
                            Err(e) => Some(ControlValue { id: v.id, value: None, auto: None, error: Some(e.to_string()) }),
                        },
                        Err(e) => Some(ControlValue { id: String::new(), value: None, auto: None, error: Some(format!("not a control value {{\"id\", \"value\"}}: {e}")) }),
                    };
                    if let Some(r) = reply {
                        let text = serde_json::to_string(&r).expect("a control value serialises");
                        if socket.send(Message::Text(text.into())).await.is_err() { break; }
                    }
                }
                Some(Ok(_)) => {}
            },
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SetValue {
    value: Option<Value>,
    auto: Option<bool>,
}

async fn set_control(
    State(app): State<Shared>,
    Path((id, control)): Path<(String, String)>,
    body: Result<Json<SetValue>, axum::extract::rejection::JsonRejection>,
) -> Response {
    if let Err(r) = known_radar(&id) {
        return r;
    }
    let Json(body) = match body {
        Ok(b) => b,
        Err(e) => {
            return refuse(
                StatusCode::BAD_REQUEST,
                format!(
                    "the body must be JSON {{\"value\": ...}} (and \"auto\" for sea clutter): {}",
                    e.body_text()
                ),
            )
        }
    };
    let v = ControlValue {
        id: control,
        value: body.value,
        auto: body.auto,
        error: None,
    };
    match app.live.set_control(&v) {
        Ok(set) => Json(set).into_response(),
        Err(e) => refuse(StatusCode::BAD_REQUEST, e.to_string()),
    }
}

fn scenario_json(app: &App) -> Value {
    let clock = app.live.clock_now();
    let time_s = app.live.time_s();
    let start_unix_s = app.description["startUnixS"].as_f64().unwrap_or(0.0);
    json!({
        "time_s": time_s,
        "unix_ms": ((start_unix_s + time_s) * 1000.0).round(),
        "speed": clock.speed(),
        "paused": clock.paused(),
        "held_s": clock.held_s(),
        "spoke_clients": app.live.spoke_clients.load(Ordering::SeqCst),
        "counters": app.live.counters(),
        "controls": app.live.controls(),
    })
}

async fn scenario(State(app): State<Shared>) -> Response {
    Json(scenario_json(&app)).into_response()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioChange {
    action: Option<String>,
    speed: Option<f64>,
}

async fn change_scenario(
    State(app): State<Shared>,
    body: Result<Json<ScenarioChange>, axum::extract::rejection::JsonRejection>,
) -> Response {
    let Json(body) = match body {
        Ok(b) => b,
        Err(e) => {
            return refuse(
                StatusCode::BAD_REQUEST,
                format!("the body must be JSON {{\"action\": \"pause\" | \"resume\" | \"restart\", \"speed\": X}}: {}", e.body_text()),
            )
        }
    };
    if let Some(speed) = body.speed {
        if let Err(e) = crate::check_speed(speed) {
            return refuse(StatusCode::BAD_REQUEST, e.to_string());
        }
    }
    match body.action.as_deref() {
        None => {}
        Some("pause") => app.live.pause(),
        Some("resume") => app.live.resume(),
        Some("restart") => app.live.restart(),
        Some(other) => {
            return refuse(
                StatusCode::BAD_REQUEST,
                format!("invalid action {other:?}: must be \"pause\", \"resume\" or \"restart\""),
            )
        }
    }
    if let Some(speed) = body.speed {
        app.live.set_speed(speed);
    }
    Json(scenario_json(&app)).into_response()
}

async fn truth(State(app): State<Shared>) -> Response {
    let Some(source) = &app.source else {
        return refuse(
            StatusCode::NOT_FOUND,
            "a replay has no truth: serve the scene to have it",
        );
    };
    let t = app.live.time_s();
    let scene = source.sim.scene();
    let geo = |p: glam::DVec3| match &source.projection {
        Some(proj) => {
            let (lon, lat) = proj.to_lon_lat_deg(p.truncate());
            (Some(lon), Some(lat))
        }
        None => (None, None),
    };
    let antenna = source.antenna_m(t);
    let own_velocity = scene
        .own_ship()
        .map_or(glam::DVec3::ZERO, |s| s.velocity_mps());
    let (lon, lat) = geo(antenna);
    let objects: Vec<Value> = scene
        .objects()
        .iter()
        .enumerate()
        .map(|(id, o)| {
            let k = o.kinematics(t);
            let b = o.local_bounds();
            let (lon, lat) = geo(k.position_m);
            json!({
                "id": id,
                "name": o.name(),
                "class": o.class(),
                "mmsi": source.mmsi.get(id).copied().flatten(),
                "structure": id >= source.mmsi.len(),
                "position_m": [k.position_m.x, k.position_m.y, k.position_m.z],
                "lon_deg": lon,
                "lat_deg": lat,
                "velocity_mps": [k.velocity_mps.x, k.velocity_mps.y],
                "speed_kn": k.speed_mps() / KNOT_M_PER_S,
                "course_deg": course_of(k.velocity_mps).map(f64::to_degrees),
                "heading_deg": k.heading_rad.to_degrees().rem_euclid(360.0),
                "length_m": b.max.y - b.min.y,
                "beam_m": b.max.x - b.min.x,
                "bow_m": b.max.y,
                "starboard_m": b.max.x,
            })
        })
        .collect();
    Json(json!({
        "time_s": t,
        "own_ship": {
            "position_m": [antenna.x, antenna.y, antenna.z],
            "lon_deg": lon,
            "lat_deg": lat,
            "velocity_mps": [own_velocity.x, own_velocity.y],
            "speed_kn": own_velocity.x.hypot(own_velocity.y) / KNOT_M_PER_S,
            "course_deg": course_of(own_velocity).map(f64::to_degrees),
            "heading_deg": source.heading_deg().rem_euclid(360.0),
        },
        "objects": objects,
    }))
    .into_response()
}
