//! `janus2d serve` end to end without a browser: the page and the scene
//! list over HTTP, then the WebSocket protocol (frames arrive, pause,
//! step, reset, draw flags, a bad scene), and the session on its own.

use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use janus2d_cli::runner::Fit;
use janus2d_cli::serve::{Control, Session, app};
use serde_json::Value;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio_tungstenite::tungstenite::Message;

async fn get(addr: std::net::SocketAddr, path: &str) -> String {
    let mut s = tokio::net::TcpStream::connect(addr).await.unwrap();
    let req = format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n");
    s.write_all(req.as_bytes()).await.unwrap();
    let mut body = String::new();
    s.read_to_string(&mut body).await.unwrap();
    body
}

type Ws =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

async fn next(ws: &mut Ws) -> Value {
    loop {
        let msg = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("a message within 10 s")
            .expect("open")
            .expect("ok");
        if let Message::Text(t) = msg {
            return serde_json::from_str(t.as_str()).unwrap();
        }
    }
}

async fn next_of(ws: &mut Ws, kind: &str) -> Value {
    loop {
        let m = next(ws).await;
        if m["type"] == kind {
            return m;
        }
    }
}

async fn send(ws: &mut Ws, json: &str) {
    ws.send(Message::Text(json.to_owned().into()))
        .await
        .unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn page_scenes_and_the_websocket_protocol() {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    tokio::spawn(async move { axum::serve(listener, app("single_box")).await });

    let page = get(addr, "/").await;
    assert!(page.starts_with("HTTP/1.1 200"), "{page}");
    assert!(page.contains("<canvas") && page.contains("/ws"));
    let scenes = get(addr, "/scenes").await;
    assert!(scenes.contains("\"single_box\"") && scenes.contains("\"tumbler\""));
    // The served scene is the one picked, and its first frame is in the
    // page as an SVG (the ground and the box), before any script runs.
    assert!(page.contains(r#"<option value="single_box" selected>"#));
    assert_eq!(page.matches(" selected>").count(), 1);
    assert!(page.contains("<svg") && page.matches("<polygon").count() >= 2);
    assert!(!page.contains("{{"), "every placeholder filled");
    // `?scene=` picks another built-in scene; a path does not load.
    let tumbler = get(addr, "/?scene=tumbler").await;
    assert!(tumbler.contains(r#"<option value="tumbler" selected>"#));
    assert!(
        tumbler.matches("<polygon").count() > 2000,
        "the drum's boxes"
    );
    let sneaky = get(addr, "/?scene=/etc/passwd").await;
    assert!(sneaky.contains(r#"<option value="single_box" selected>"#));

    let (mut ws, _) = tokio_tungstenite::connect_async(format!("ws://{addr}/ws"))
        .await
        .unwrap();
    let scene = next_of(&mut ws, "scene").await;
    assert_eq!(scene["name"], "single_box");
    assert_eq!(scene["bounds"].as_array().unwrap().len(), 4);
    // Frames arrive and the steps go on.
    let a = next_of(&mut ws, "frame").await;
    let b = next_of(&mut ws, "frame").await;
    assert!(b["step"].as_u64() > a["step"].as_u64());
    assert_eq!(a["bodies"], 2);
    let prims = a["prims"].as_array().unwrap();
    assert!(prims.iter().any(|p| p[0] == "P"), "the box as a polygon");

    // Pause: the step stops moving.
    send(&mut ws, r#"{"cmd":"pause"}"#).await;
    let mut paused = next_of(&mut ws, "frame").await;
    while paused["running"] == true {
        paused = next_of(&mut ws, "frame").await;
    }
    let still = next_of(&mut ws, "frame").await;
    assert_eq!(still["step"], paused["step"]);
    // Step once.
    send(&mut ws, r#"{"cmd":"step"}"#).await;
    let mut stepped = next_of(&mut ws, "frame").await;
    while stepped["step"] == paused["step"] {
        stepped = next_of(&mut ws, "frame").await;
    }
    assert_eq!(
        stepped["step"].as_u64(),
        paused["step"].as_u64().map(|s| s + 1)
    );
    // Draw flags: boxes appear as outlines.
    send(&mut ws, r#"{"cmd":"draw","flags":"aabbs"}"#).await;
    let mut f = next_of(&mut ws, "frame").await;
    while !f["prims"].as_array().unwrap().iter().any(|p| p[0] == "p") {
        f = next_of(&mut ws, "frame").await;
    }
    // A bad scene and a bad control are errors, and the session goes on.
    send(&mut ws, r#"{"cmd":"scene","name":"no_such_scene"}"#).await;
    let e = next_of(&mut ws, "error").await;
    assert!(e["message"].as_str().unwrap().contains("no_such_scene"));
    send(&mut ws, r#"{"cmd":"fly"}"#).await;
    let e = next_of(&mut ws, "error").await;
    assert!(e["message"].as_str().unwrap().contains("bad control"));
    // Reset and another scene.
    send(&mut ws, r#"{"cmd":"reset"}"#).await;
    next_of(&mut ws, "scene").await;
    let f = next_of(&mut ws, "frame").await;
    assert!(f["step"].as_u64().unwrap() <= 1);
    send(&mut ws, r#"{"cmd":"scene","name":"bridge"}"#).await;
    let s = next_of(&mut ws, "scene").await;
    assert_eq!(s["name"], "bridge");
    ws.close(None).await.unwrap();
}

#[test]
fn the_session_applies_controls() {
    let mut s = Session::new("single_box").unwrap();
    assert!(s.running());
    s.apply(Control::Step).unwrap();
    assert!(!s.running());
    assert_eq!(s.step_count(), 1);
    s.apply(Control::Substeps { n: 8 }).unwrap();
    assert_eq!(s.scene().world().settings().substeps, 8);
    assert!(s.apply(Control::Substeps { n: 0 }).is_err());
    assert!(
        s.apply(Control::Draw {
            flags: "bogus".into()
        })
        .is_err()
    );
    assert!(s.apply(Control::Reset).unwrap().is_some());
    assert_eq!(s.step_count(), 0);
    let frame: Value = serde_json::from_str(&s.frame()).unwrap();
    assert_eq!(frame["type"], "frame");
    // Knobs.
    s.apply(Control::Knob {
        name: "contact_hertz".into(),
        value: 45.0,
    })
    .unwrap();
    assert_eq!(s.scene().world().settings().contact_hertz, 45.0);
    s.apply(Control::Knob {
        name: "warm_starting".into(),
        value: 0.0,
    })
    .unwrap();
    assert!(!s.scene().world().settings().warm_starting);
    s.apply(Control::Knob {
        name: "gravity".into(),
        value: -5.0,
    })
    .unwrap();
    assert_eq!(s.scene().world().gravity().y, -5.0);
    assert!(
        s.apply(Control::Knob {
            name: "colour".into(),
            value: 1.0
        })
        .is_err()
    );
    assert!(
        s.apply(Control::Knob {
            name: "contact_hertz".into(),
            value: f64::NAN
        })
        .is_err()
    );
    let c: Control = serde_json::from_str(r#"{"cmd":"scene","name":"tumbler"}"#).unwrap();
    assert_eq!(
        c,
        Control::Scene {
            name: "tumbler".into()
        }
    );
}

/// A drag pulls the body to the target through a mouse joint (gone on
/// release, with its static body); a click on nothing grabs nothing;
/// shift-click drops a box.
#[test]
fn grab_drag_and_spawn() {
    let mut s = Session::new("single_box").unwrap();
    // single_box: a unit box resting on the ground at (0, 0.5)..; find it.
    let world = s.scene().world();
    let body = world
        .body_handles()
        .find(|&b| world.body_type(b) == Ok(janus2d_core::body::BodyType::Dynamic))
        .unwrap();
    let p = world.position(body).unwrap();
    let (x, y) = (
        janus2d_core::math::to_f64(p.x),
        janus2d_core::math::to_f64(p.y),
    );
    let (bodies, joints) = (world.body_count(), world.joint_count());
    s.apply(Control::Grab { x: x + 100.0, y }).unwrap();
    assert_eq!(s.grabbed(), None, "nothing under the cursor");
    assert_eq!(s.scene().world().joint_count(), joints);
    s.apply(Control::Grab { x, y }).unwrap();
    assert_eq!(s.grabbed(), Some(body));
    let joint = s.grab_joint().expect("a mouse joint");
    {
        let w = s.scene().world();
        let mouse = w
            .joint_of::<janus2d_constraints::MouseJoint>(joint)
            .unwrap();
        assert_eq!(mouse.def().base.body_b, body);
        assert_eq!(
            w.body_type(mouse.def().base.body_a),
            Ok(janus2d_core::body::BodyType::Static)
        );
        assert_eq!((w.body_count(), w.joint_count()), (bodies + 1, joints + 1));
    }
    s.apply(Control::Drag {
        x: x + 3.0,
        y: y + 2.0,
    })
    .unwrap();
    for _ in 0..120 {
        s.advance().unwrap();
    }
    let q = s.scene().world().position(body).unwrap();
    assert!(
        (janus2d_core::math::to_f64(q.x) - (x + 3.0)).abs() < 0.3,
        "pulled to the target: {q:?}"
    );
    assert!(
        (janus2d_core::math::to_f64(q.y) - (y + 2.0)).abs() < 0.3,
        "held up against gravity: {q:?}"
    );
    let target = s
        .scene()
        .world()
        .joint_of::<janus2d_constraints::MouseJoint>(joint)
        .unwrap()
        .def()
        .target;
    assert_eq!(
        (target.x, target.y),
        (
            janus2d_core::math::from_f64(x + 3.0),
            janus2d_core::math::from_f64(y + 2.0)
        )
    );
    s.apply(Control::Release).unwrap();
    assert_eq!(s.grabbed(), None);
    assert_eq!(s.grab_joint(), None);
    let w = s.scene().world();
    assert_eq!((w.body_count(), w.joint_count()), (bodies, joints));
    assert!(w.joint(joint).is_err(), "the mouse joint is gone");
    // A reset during a drag starts clean.
    s.apply(Control::Grab {
        x: x + 3.0,
        y: y + 2.0,
    })
    .unwrap();
    assert!(s.grabbed().is_some());
    s.apply(Control::Reset).unwrap();
    assert_eq!(s.grabbed(), None);
    s.apply(Control::Drag { x, y }).unwrap();
    s.apply(Control::Release).unwrap();
    let before = s.scene().world().body_count();
    s.apply(Control::Spawn { x: 2.0, y: 5.0 }).unwrap();
    assert_eq!(s.scene().world().body_count(), before + 1);
    assert!(
        s.apply(Control::Spawn {
            x: f64::NAN,
            y: 0.0
        })
        .is_err()
    );
}

/// `--fit each` sends the bounds with every frame; `once` never.
#[test]
fn the_page_camera_follows_fit() {
    let mut each = Session::with_fit("single_box", Fit::Each).unwrap();
    let mut once = Session::new("single_box").unwrap();
    for _ in 0..3 {
        each.advance().unwrap();
        once.advance().unwrap();
        let e: Value = serde_json::from_str(&each.next_frame()).unwrap();
        let o: Value = serde_json::from_str(&once.next_frame()).unwrap();
        assert_eq!(e["fit"].as_array().unwrap().len(), 4);
        assert!(o["fit"].is_null());
    }
    let mut every = Session::with_fit("single_box", Fit::Every(2)).unwrap();
    let mut sent = Vec::new();
    for _ in 0..4 {
        every.advance().unwrap();
        let f: Value = serde_json::from_str(&every.next_frame()).unwrap();
        sent.push(!f["fit"].is_null());
    }
    assert_eq!(sent, [false, true, false, true]);
}

/// The page is sent every joint kind of `joint_zoo`: with the joints flag
/// on, the frame holds at least one more primitive per joint than with it
/// off (whatever the debug draw draws per kind).
#[test]
fn the_page_draws_every_joint_kind() {
    let mut s = Session::new("joint_zoo").unwrap();
    let joints = s.scene().world().joint_count();
    assert_eq!(joints, 10);
    let count = |s: &Session| -> usize {
        let v: Value = serde_json::from_str(&s.frame()).unwrap();
        v["prims"].as_array().unwrap().len()
    };
    s.apply(Control::Draw {
        flags: "-joints".into(),
    })
    .unwrap();
    let without = count(&s);
    s.apply(Control::Draw {
        flags: "+joints".into(),
    })
    .unwrap();
    let with = count(&s);
    assert!(with >= without + joints, "{with} vs {without}");
    // Dragging adds the mouse joint, drawn too.
    let b = s.scene().probe.expect("the zoo's pulled box");
    let p = s.scene().world().position(b).unwrap();
    let (x, y) = (
        janus2d_core::math::to_f64(p.x),
        janus2d_core::math::to_f64(p.y),
    );
    s.apply(Control::Grab { x, y }).unwrap();
    assert_eq!(s.grabbed(), Some(b));
    s.apply(Control::Drag {
        x: x + 1.0,
        y: y + 1.0,
    })
    .unwrap();
    assert!(count(&s) > with, "the drag's joint is drawn");
}
