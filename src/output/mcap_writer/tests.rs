use super::super::mcap_messages::message_json;
use super::super::scene;
use super::super::test_support::Sample;
use super::*;
use serde_json::Value;
use std::path::Path;

fn write_sample(path: &Path, s: &Sample, times: &[f64], encoding: Encoding) {
    let mut w = McapWriter::new(File::create(path).unwrap(), &s.topology(), encoding).unwrap();
    for (f, &t) in times.iter().enumerate() {
        let mut frame = s.frame(f);
        frame.time = t;
        w.write_frame(&frame).unwrap();
    }
    Box::new(w).finish().unwrap();
}

#[test]
fn schemas_are_valid_json() {
    for (name, schema) in [
        ("cellmd.Topology", TOPOLOGY_SCHEMA),
        ("cellmd.Frame", FRAME_SCHEMA),
        ("cellmd.BondState", BOND_STATE_SCHEMA),
        ("cellmd.BondEvents", BOND_EVENTS_SCHEMA),
        ("foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA),
    ] {
        let v: Value = serde_json::from_str(schema).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(v["title"], name);
    }
}

/// The file is chunked with zstd, and both encodings carry the same
/// messages on every channel: protobuf decoded equals the JSON written.
#[test]
fn chunks_are_zstd_and_both_encodings_agree() {
    let s = Sample::new(2);
    let dir = tempfile::tempdir().unwrap();
    let mut messages = Vec::new();
    for (encoding, name) in [(Encoding::Protobuf, "p.mcap"), (Encoding::Json, "j.mcap")] {
        let path = dir.path().join(name);
        write_sample(&path, &s, &[0.1, 0.2], encoding);
        let bytes = std::fs::read(&path).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        assert!(!summary.chunk_indexes.is_empty());
        assert!(summary.chunk_indexes.iter().all(|c| c.compression == "zstd"), "{:?}", summary.chunk_indexes);
        let scene = summary.channels.values().find(|c| c.topic == TOPIC_SCENE).unwrap();
        let schema = scene.schema.as_ref().unwrap();
        assert_eq!(schema.name, "foxglove.SceneUpdate");
        let want = match encoding {
            Encoding::Protobuf => ("protobuf", "protobuf"),
            Encoding::Json => ("json", "jsonschema"),
        };
        assert_eq!((scene.message_encoding.as_str(), schema.encoding.as_str()), want);
        if encoding == Encoding::Protobuf {
            // The schema is a FileDescriptorSet that declares foxglove.SceneUpdate.
            let set = <prost_types::FileDescriptorSet as prost::Message>::decode(&schema.data[..]).unwrap();
            assert!(set.file.iter().any(|f| f.package() == "foxglove" && f.message_type.iter().any(|m| m.name() == "SceneUpdate")));
        }
        let stream = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap());
        messages.push(stream.map(|m| (m.channel.topic.clone(), message_json(&m).unwrap())).collect::<Vec<_>>());
    }
    // topology, bond state, then frame and scene twice.
    assert_eq!(messages[0].len(), 6);
    assert_eq!(messages[0], messages[1]);
}

#[test]
fn three_frames_read_back() {
    let s = Sample::new(3);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.mcap");
    // The second and third times collide at ns resolution: stamps are forced up.
    let times = [0.1, 0.2, 0.2 + 1e-12];
    write_sample(&path, &s, &times, Encoding::Protobuf);
    let bytes = std::fs::read(&path).unwrap();

    let summary = mcap::Summary::read(&bytes).unwrap().expect("summary section");
    let stats = summary.stats.expect("statistics");
    assert_eq!(stats.message_count, 1 + 1 + 3 + 3);
    // topology, frame, bond state, scene and (empty here) bond events.
    assert_eq!(summary.channels.len(), 5);

    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let mut frame_stamps = Vec::new();
    let mut frames = Vec::new();
    let mut scenes = Vec::new();
    let mut topology = None;
    let mut bond_state = None;
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        let channel = &message.channel;
        let schema = channel.schema.as_ref().expect("every channel has a schema");
        let expected_schema = match channel.topic.as_str() {
            TOPIC_TOPOLOGY => "cellmd.Topology",
            TOPIC_FRAME => "cellmd.Frame",
            TOPIC_BOND_STATE => "cellmd.BondState",
            TOPIC_SCENE => "foxglove.SceneUpdate",
            other => panic!("unexpected topic {other}"),
        };
        assert_eq!(schema.name, expected_schema);
        if channel.topic != TOPIC_SCENE {
            assert_eq!(channel.message_encoding, "protobuf");
            assert_eq!(schema.encoding, "protobuf");
            assert_eq!(schema.data, descriptor_set());
        }
        assert_eq!(message.log_time, message.publish_time);
        *counts.entry(channel.topic.clone()).or_default() += 1;
        match channel.topic.as_str() {
            TOPIC_TOPOLOGY => topology = Some(message_json(&message).unwrap()),
            TOPIC_BOND_STATE => bond_state = Some(message_json(&message).unwrap()),
            TOPIC_FRAME => {
                frame_stamps.push(message.log_time);
                frames.push(message_json(&message).unwrap());
            }
            _ => scenes.push((message.log_time, message_json(&message).unwrap())),
        }
    }
    assert_eq!(counts[TOPIC_TOPOLOGY], 1);
    assert_eq!(counts[TOPIC_BOND_STATE], 1);
    assert_eq!(counts[TOPIC_FRAME], 3);
    assert_eq!(counts[TOPIC_SCENE], 3);
    assert_eq!(frame_stamps, vec![100_000_000, 200_000_000, 200_000_001]);

    let topology = topology.unwrap();
    assert_eq!(topology["units"], "cell");
    assert_eq!(topology["ids"], serde_json::json!([40, 7, 12, 3]));
    assert_eq!(topology["type_names"], serde_json::json!(["cortex", "adhesion site"]));
    assert_eq!(topology["types"], serde_json::json!([0, 1, 1, 0]));
    assert_eq!(topology["radii"], serde_json::json!([0.25, 0.0, 0.0, 0.25]));
    assert_eq!(topology["bonds"], serde_json::json!([[7, 12], [40, 3]]));
    assert_eq!(topology["angles"], serde_json::json!([[40, 7, 12]]));
    assert_eq!(topology["triangles"], serde_json::json!([[40, 7, 3]]));
    let bond_state = bond_state.unwrap();
    assert_eq!(bond_state["bound"], serde_json::json!([true, true]));
    assert_eq!(bond_state["step"], 0);

    for (f, frame) in frames.iter().enumerate() {
        assert_eq!(frame["step"], 100 * f as u64);
        assert_eq!(frame["time"].as_f64().unwrap().to_bits(), times[f].to_bits());
        assert_eq!(frame["box"]["lo"], serde_json::json!([0.0, 0.0, -5.0]));
        assert_eq!(frame["box"]["periodic"], serde_json::json!([true, true, false]));
        let flat: Vec<f64> = frame["positions"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        assert_eq!(flat.len(), 12);
        for (i, x) in s.frames[f].iter().enumerate() {
            for a in 0..3 {
                assert_eq!(flat[3 * i + a].to_bits(), x[a].to_bits(), "frame {f} particle {i} axis {a}");
            }
        }
        let images: Vec<i64> = frame["images"].as_array().unwrap().iter().map(|v| v.as_i64().unwrap()).collect();
        assert_eq!(images, s.images.iter().flatten().copied().collect::<Vec<_>>());
    }

    let (stamp, scene) = &scenes[0];
    assert_eq!(*stamp, 100_000_000);
    let entity = &scene["entities"][0];
    assert_eq!(entity["frame_id"], "world");
    assert_eq!(entity["id"], "particles");
    assert_eq!(entity["timestamp"], serde_json::json!({"sec": 0, "nsec": 100_000_000}));
    let spheres = entity["spheres"].as_array().unwrap();
    assert_eq!(spheres.len(), 4);
    assert_eq!(spheres[0]["size"]["x"], 0.5);
    assert_eq!(spheres[1]["size"]["x"], 2.0 * scene::DEFAULT_RADIUS);
    assert_eq!(spheres[1]["pose"]["position"]["x"], 9.95);
    assert_ne!(spheres[0]["color"], spheres[1]["color"]);
    assert_eq!(spheres[1]["color"], spheres[2]["color"]);
    let lines = entity["lines"].as_array().unwrap();
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0]["type"], 2);
    let points = lines[0]["points"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    // Bond 7–12 crosses the periodic x face: 9.95 → 9.95 + 0.1, not 0.05.
    assert_eq!(points[0]["x"], 9.95);
    assert!((points[1]["x"].as_f64().unwrap() - 10.05).abs() < 1e-12);
    // The surface: one triangle list, three points per face, each face whole.
    let triangles = entity["triangles"].as_array().unwrap();
    assert_eq!(triangles.len(), 1);
    let corners = triangles[0]["points"].as_array().unwrap();
    assert_eq!(corners.len(), 3 * s.triangles.len());
    let xs: Vec<f64> = corners.iter().map(|p| p["x"].as_f64().unwrap()).collect();
    assert!(xs.iter().all(|x| (x - xs[0]).abs() < 5.0), "a face split across the periodic box: {xs:?}");
    for key in ["arrows", "cubes", "cylinders", "texts", "models", "metadata"] {
        assert_eq!(entity[key], serde_json::json!([]), "{key}");
    }
    // The box: its 12 edges, and no walls in this frame.
    let frame_box = &scene["entities"][1];
    assert_eq!(frame_box["id"], "box");
    assert_eq!(frame_box["lines"][0]["points"].as_array().unwrap().len(), 24);
    assert_eq!(frame_box["triangles"], serde_json::json!([]));
}

/// A message between frames is in a whole chunk on disk once it has
/// waited the batch interval, and a streaming reader recovers it from
/// the unfinished file (as after a kill).
#[test]
fn messages_between_frames_are_written_within_the_batch_interval() {
    let s = Sample::new(2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.mcap");
    let mut w = McapWriter::new(File::create(&path).unwrap(), &s.topology(), Encoding::Protobuf).unwrap();
    w.write_frame(&s.frame(0)).unwrap();
    let after_frame = std::fs::metadata(&path).unwrap().len();
    w.write_bond_state(50, 0.05, &[true, false]).unwrap();
    w.flush_due().unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), after_frame, "a message waits up to the interval");
    std::thread::sleep(BATCH_INTERVAL);
    w.flush_due().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert!(bytes.len() as u64 > after_frame);
    let stream = mcap::MessageStream::new_with_options(&bytes, mcap::read::Options::IgnoreEndMagic.into()).unwrap();
    let topics: Vec<String> = stream.map_while(Result::ok).map(|m| m.channel.topic.clone()).collect();
    assert_eq!(topics.last().map(String::as_str), Some(TOPIC_BOND_STATE), "{topics:?}");
    let len = bytes.len();
    w.flush_due().unwrap();
    assert_eq!(std::fs::read(&path).unwrap().len(), len, "nothing new, nothing written");
}

#[test]
fn later_bond_states_and_scene_toggle() {
    let s = Sample::new(2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.mcap");
    let mut w = McapWriter::new(File::create(&path).unwrap(), &s.topology(), Encoding::Protobuf).unwrap();
    w.write_frame(&s.frame(0)).unwrap();
    w.write_bond_state(50, 0.05, &[true, false]).unwrap();
    assert!(w.write_bond_state(50, 0.05, &[true]).is_err());
    w.set_scene(false);
    w.write_frame(&s.frame(1)).unwrap();
    Box::new(w).finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let mut states = Vec::new();
    let mut scenes = 0;
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        match message.channel.topic.as_str() {
            TOPIC_BOND_STATE => {
                assert_eq!(message.sequence as usize, states.len() + 1);
                states.push(message_json(&message).unwrap()["bound"].clone());
            }
            TOPIC_SCENE => scenes += 1,
            _ => {}
        }
    }
    assert_eq!(states, vec![serde_json::json!([true, true]), serde_json::json!([true, false])]);
    assert_eq!(scenes, 1);
}

#[test]
fn time_stamps_round_and_clamp() {
    assert_eq!(time_ns(1.5e-9), 2);
    assert_eq!(time_ns(-3.0), 0);
    assert_eq!(time_ns(f64::NAN), 0);
    assert_eq!(time_ns(1e30), u64::MAX);
}
