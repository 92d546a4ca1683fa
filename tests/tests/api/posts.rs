//! Every post's program of every capability, read by an interpreter no one here wrote where one
//! installs from the registries: LinuxCNC's `rs274` for the LinuxCNC, Fanuc and Haas posts, PyPI
//! `nc-gcode-interpreter` (Sinumerik-flavoured) for the 840D post, PyPI `pygcode` for grbl (with
//! grbl 1.1's word list and line length checked here). The Heidenhain posts have no interpreter
//! on the registries: a reader here checks their structure (numbered blocks, the tool call
//! before the moves, every arc's centre as far from its start as from its end). Every post's moves
//! are those of the LinuxCNC program as `rs274` reads it, within 1e-4 mm (Heidenhain's: in order
//! among its own, which add the chords of helical arcs).

use std::io::Write as _;

use kerf_tests::{TestApp, external_program, json_with, rs274_moves};
use serde_json::{Value, json};

/// A move: whether it feeds (else a rapid), and its end point.
type Move = (bool, [f64; 3]);

/// One request of every capability: deburr (stored tool 7), segment (no tool), contour (stored
/// tool 3, arcs as G02/G03), engagement (stored tool 3, arcs as G02/G03), predict (a path of
/// points, inline tool number 3).
fn requests() -> Vec<(&'static str, String, Value)> {
    let mut predict = crate::predict::raster_request(crate::predict::finishing_tool(), 1, 2);
    let points: Vec<[f64; 3]> = (0..=16).map(|i| [-4.0 + 0.5 * f64::from(i), 0.0, 0.0]).collect();
    predict["path"] = json!({"kind": "points", "points": points});
    predict["feed"] = json!(1600);
    predict["spindle_rpm"] = json!(8000);
    predict["tool"]["number"] = json!(3);
    vec![
        ("deburr", "deburr".to_owned(), kerf_cases::deburr::tube_request()),
        (
            "segment",
            "segment".to_owned(),
            json!({"curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [40, 15]}, "feed": 3000,
                   "block_time_ms": 4, "mode": "guarantee"}),
        ),
        ("contour", "contour?arcs=g2g3".to_owned(), kerf_cases::contour::arrow_request(2)),
        (
            "engagement",
            "engagement?arcs=g2g3".to_owned(),
            json!({"tool": 3, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
                   "path": [[-10, 5], [70, 5], [70, 15], [-10, 15], [-10, 25], [70, 25]],
                   "spindle_rpm": 8000, "feed_per_tooth": 0.05, "axial_depth": 2}),
        ),
        ("predict", "predict".to_owned(), predict),
    ]
}

/// The service with the stored tools the requests name.
async fn app() -> TestApp {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3, "flutes": 3})).await;
    app
}

/// The program of `body` at `endpoint` (with its query) in `dialect`.
async fn program(app: &TestApp, endpoint: &str, body: &Value, dialect: &str) -> String {
    let separator = if endpoint.contains('?') { '&' } else { '?' };
    let url = app.url(&format!("/api/v1/{endpoint}{separator}format=gcode&dialect={dialect}"));
    let response = app.client.post(url).json(body).send().await.unwrap();
    assert_eq!(response.status(), 200, "{endpoint} {dialect}");
    response.text().await.unwrap()
}

/// Every program's moves in the LinuxCNC post as `rs274` reads them, by capability.
async fn linuxcnc_moves(app: &TestApp) -> Vec<(&'static str, String, Value, Vec<Move>)> {
    let mut all = Vec::new();
    for (name, endpoint, body) in requests() {
        let text = program(app, &endpoint, &body, "linuxcnc").await;
        let moves = rs274_moves(&text, app.directory(), &format!("{name}_linuxcnc")).expect("rs274 present");
        assert!(moves.iter().filter(|m| m.0).count() > 3, "{name}: {text}");
        all.push((name, endpoint, body, moves));
    }
    all
}

/// `got` equals `want` in count, kind and end point within 1e-4 mm.
fn assert_same_moves(label: &str, got: &[Move], want: &[Move]) {
    assert_eq!(got.len(), want.len(), "{label}: move count");
    for (index, (got, want)) in got.iter().zip(want).enumerate() {
        assert_eq!(got.0, want.0, "{label}: move {index} kind");
        assert!((0..3).all(|k| (got.1[k] - want.1[k]).abs() <= 1e-4), "{label}: move {index} {got:?} vs {want:?}");
    }
}

/// `want` appears in order among `got` (end points within 1e-4 mm).
fn assert_moves_among(label: &str, got: &[Move], want: &[Move]) {
    let mut rest = got.iter();
    for (index, want) in want.iter().enumerate() {
        let found = rest.any(|got| got.0 == want.0 && (0..3).all(|k| (got.1[k] - want.1[k]).abs() <= 1e-4));
        assert!(found, "{label}: move {index} {want:?} is not among the program's moves in order");
    }
}

/// Runs `script` with `python3` on `program` (its standard input); its standard output as JSON.
pub(crate) fn python(script: &str, program: &str, label: &str) -> Value {
    let python = external_program("python3", "the PyPI G-code interpreters").expect("python3");
    let mut child = std::process::Command::new(python)
        .args(["-c", script])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("python3 runs");
    child.stdin.take().unwrap().write_all(program.as_bytes()).unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(output.status.success(), "{label}: {}\n{program}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_slice(&output.stdout).unwrap_or_else(|e| panic!("{label}: {e}"))
}

/// Moves as the Python scripts print them: `[[feed, x, y, z], ...]`.
pub(crate) fn moves_of(value: &Value) -> Vec<Move> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            let n = |k: usize| m[k].as_f64().unwrap();
            (m[0].as_bool().unwrap(), [n(1), n(2), n(3)])
        })
        .collect()
}

/// Sinumerik: `nc_to_dataframe` reads the program as an 840D does; every block that names an
/// axis is a move to the modal position.
pub(crate) const SINUMERIK: &str = r#"
import json, sys
import nc_gcode_interpreter as nc
frame, state = nc.nc_to_dataframe(sys.stdin.read(), disable_forward_fill=True)
position, moves, motion = [0.0, 0.0, 0.0], [], None
for row in frame.iter_rows(named=True):
    if row.get("gg01_motion"):
        motion = row["gg01_motion"]
    given = [row.get(axis) for axis in "XYZ"]
    if all(value is None for value in given):
        continue
    position = [old if new is None else new for old, new in zip(position, given)]
    moves.append([motion in ("G1", "G2", "G3"), *position])
print(json.dumps(moves))
"#;

/// grbl: pygcode parses every line and keeps the machine position; every motion block is a move.
const GRBL: &str = r#"
import json, sys
from pygcode import Line, Machine, GCodeRapidMove, GCodeLinearMove, GCodeArcMove
machine, moves = Machine(), []
for text in sys.stdin.read().splitlines():
    block = Line(text).block
    machine.process_block(block)
    motion = [g for g in block.gcodes if isinstance(g, (GCodeRapidMove, GCodeLinearMove, GCodeArcMove))]
    if motion:
        p = machine.pos
        moves.append([not isinstance(motion[0], GCodeRapidMove), p.X, p.Y, p.Z])
print(json.dumps(moves))
"#;

/// grbl 1.1's G and M codes and words (its wiki, "Grbl v1.1 Commands"): anything else is an
/// error on the control.
fn check_grbl_words(label: &str, text: &str) {
    const CODES: [&str; 24] = [
        "G0", "G1", "G2", "G3", "G4", "G17", "G18", "G19", "G20", "G21", "G40", "G49", "G53", "G54", "G80", "G90",
        "G91", "G93", "G94", "M0", "M2", "M30", "M5", "M9",
    ];
    const MORE: [&str; 5] = ["M3", "M4", "M7", "M8", "M1"];
    for line in text.lines() {
        assert!(line.len() <= 80, "{label}: a line longer than grbl's buffer: {line}");
        let words = line.split_once('(').map_or(line, |(before, _)| before);
        for word in words.split_whitespace() {
            let (letter, value) = word.split_at(1);
            assert!(value.parse::<f64>().is_ok(), "{label}: word {word} in {line}");
            match letter {
                "G" | "M" => {
                    assert!(CODES.contains(&word) || MORE.contains(&word), "{label}: grbl has no {word}: {line}")
                }
                "X" | "Y" | "Z" | "I" | "J" | "F" | "S" => {}
                _ => panic!("{label}: grbl takes no {letter} word here: {line}"),
            }
        }
    }
}

/// A signed number of Heidenhain's format: `+12.3400`, `-0.5000`.
fn signed(word: &str) -> Option<f64> {
    (word.starts_with('+') || word.starts_with('-')).then_some(())?;
    word.parse().ok()
}

/// Reads a Klartext program: block numbers from 0 up, `BEGIN PGM` and `END PGM` with one name,
/// only the blocks the post writes, the tool call before any move, every `C` right after its
/// `CC` with the centre as far from the start as from the end; its moves.
pub(crate) fn read_klartext(label: &str, text: &str) -> Vec<Move> {
    let lines: Vec<&str> = text.lines().collect();
    let mut blocks = Vec::new();
    for (index, line) in lines.iter().enumerate() {
        let (number, block) = line.split_once(' ').unwrap_or_else(|| panic!("{label}: {line}"));
        assert_eq!(number.parse::<usize>().ok(), Some(index), "{label}: block number of {line}");
        blocks.push(block);
    }
    let name = blocks[0].strip_prefix("BEGIN PGM ").and_then(|b| b.strip_suffix(" MM")).expect("BEGIN PGM");
    assert_eq!(blocks[blocks.len() - 1], format!("END PGM {name} MM"), "{label}");
    let (mut position, mut moves, mut centre) = ([0.0f64; 3], Vec::new(), None::<[f64; 2]>);
    let (mut tool_called, mut feed_given) = (false, false);
    for block in &blocks[1..blocks.len() - 1] {
        if block.starts_with("; ") {
            continue;
        }
        if *block == "STOP" {
            // The operator loads a tool the table does not have.
            tool_called = true;
            continue;
        }
        if let Some(call) = block.strip_prefix("TOOL CALL ") {
            let words: Vec<&str> = call.split(' ').collect();
            // `TOOL CALL [n] Z [S…]`: a call without a tool sets the speed, one without a speed keeps it.
            let speed = words.last().and_then(|w| w.strip_prefix('S')).map(|s| s.parse::<u32>().is_ok());
            let tool = words[0] == "Z" || (words[0].parse::<u32>().is_ok() && words.get(1) == Some(&"Z"));
            assert!(tool && speed != Some(false) && words.len() <= 3, "{label}: {block}");
            assert!(speed.is_some() || words[0] != "Z", "{label}: a tool call that does nothing: {block}");
            tool_called = true;
            continue;
        }
        let mut words = block.split(' ');
        let kind = words.next().unwrap();
        let mut axes = [None; 3];
        let (mut rapid, mut direction) = (false, None);
        for word in words {
            match word {
                "R0" => {}
                "FMAX" => rapid = true,
                "DR+" | "DR-" => direction = Some(word),
                "M1" | "M2" | "M3" | "M4" | "M5" | "M7" | "M8" | "M9" | "M30" => {}
                _ if word.starts_with('F') => {
                    assert!(word[1..].parse::<f64>().is_ok_and(|f| f > 0.0), "{label}: {block}");
                    feed_given = true;
                }
                _ => {
                    let axis = "XYZ".find(&word[..1]).unwrap_or_else(|| panic!("{label}: word {word} in {block}"));
                    axes[axis] = Some(signed(&word[1..]).unwrap_or_else(|| panic!("{label}: {word} in {block}")));
                }
            }
        }
        match kind {
            "CC" => {
                centre = Some([axes[0].expect("CC X"), axes[1].expect("CC Y")]);
                continue;
            }
            "C" => {
                let c = centre.take().unwrap_or_else(|| panic!("{label}: C without its CC: {block}"));
                assert!(direction.is_some(), "{label}: {block}");
                let end = [axes[0].expect("C X"), axes[1].expect("C Y")];
                let (from, to) = ((position[0] - c[0]).hypot(position[1] - c[1]), (end[0] - c[0]).hypot(end[1] - c[1]));
                assert!((from - to).abs() <= 2e-3, "{label}: arc radii {from} and {to}: {block}");
                position[0] = end[0];
                position[1] = end[1];
            }
            "L" => {
                assert!(centre.is_none(), "{label}: CC not followed by C");
                for (axis, value) in axes.iter().enumerate() {
                    if let Some(value) = value {
                        position[axis] = *value;
                    }
                }
            }
            _ => panic!("{label}: unknown block {block}"),
        }
        let is_move = kind == "C" || axes[0].is_some();
        if is_move || axes[2].is_some() {
            assert!(tool_called, "{label}: a move before the tool call: {block}");
            assert!(rapid || feed_given, "{label}: a feed move before any feed: {block}");
            moves.push((!rapid, position));
        }
    }
    moves
}

/// Reads a Heidenhain ISO program: `%NAME G71 *` first and `N99999999 %NAME G71 *` last, blocks
/// `N…` numbered up in tens and ending in ` *`, the words the post writes, the tool call before
/// any move, every G02/G03 right after its absolute `I J` centre; its moves.
fn read_heidenhain_iso(label: &str, text: &str) -> Vec<Move> {
    let lines: Vec<&str> = text.lines().collect();
    let name = lines[0].strip_prefix('%').and_then(|l| l.strip_suffix(" G71 *")).expect("%NAME G71 *");
    assert_eq!(lines[lines.len() - 1], format!("N99999999 %{name} G71 *"), "{label}");
    let (mut position, mut moves, mut centre) = ([0.0f64; 3], Vec::new(), None::<[f64; 2]>);
    let (mut tool_called, mut feed_given, mut last) = (false, false, 0);
    for line in &lines[1..lines.len() - 1] {
        let rest = line.strip_prefix('N').unwrap_or_else(|| panic!("{label}: {line}"));
        let (number, block) = rest.split_once(' ').unwrap();
        let number: u32 = number.parse().unwrap();
        assert_eq!(number, last + 10, "{label}: {line}");
        last = number;
        let block = block.strip_suffix(" *").unwrap_or_else(|| panic!("{label}: no block end: {line}"));
        if block.starts_with("; ") {
            continue;
        }
        let mut code = None;
        let mut axes = [None; 3];
        let mut ij = [None; 2];
        for word in block.split(' ') {
            let (letter, value) = word.split_at(1);
            match letter {
                "G" => {
                    let g: u32 = value.parse().unwrap_or_else(|_| panic!("{label}: {word}"));
                    assert!([0, 1, 2, 3, 17, 40, 90].contains(&g), "{label}: {word} in {line}");
                    if g <= 3 {
                        code = Some(g);
                    }
                }
                "M" => {
                    assert!(["00", "03", "04", "05", "08", "07", "09", "30"].contains(&value), "{label}: {line}");
                    // M00: the operator loads a tool the table does not have.
                    tool_called |= value == "00";
                }
                "T" => {
                    assert!(value.parse::<u32>().is_ok() && block.ends_with(" G17"), "{label}: {line}");
                    tool_called = true;
                }
                "S" => assert!(value.parse::<u32>().is_ok(), "{label}: {line}"),
                "F" => {
                    assert!(value.parse::<f64>().is_ok_and(|f| f > 0.0), "{label}: {line}");
                    feed_given = true;
                }
                "X" | "Y" | "Z" => axes["XYZ".find(letter).unwrap()] = Some(signed(value).expect("a signed number")),
                "I" | "J" => ij["IJ".find(letter).unwrap()] = Some(signed(value).expect("a signed number")),
                _ => panic!("{label}: word {word} in {line}"),
            }
        }
        if let [Some(i), Some(j)] = ij {
            centre = Some([i, j]);
            continue;
        }
        let Some(code) = code else { continue };
        let before = position;
        for (axis, value) in axes.iter().enumerate() {
            if let Some(value) = value {
                position[axis] = *value;
            }
        }
        if code >= 2 {
            let c = centre.take().unwrap_or_else(|| panic!("{label}: G0{code} without its centre: {line}"));
            let (from, to) =
                ((before[0] - c[0]).hypot(before[1] - c[1]), (position[0] - c[0]).hypot(position[1] - c[1]));
            assert!((from - to).abs() <= 2e-3, "{label}: arc radii {from} and {to}: {line}");
        }
        assert!(tool_called, "{label}: a move before the tool call: {line}");
        assert!(code == 0 || feed_given, "{label}: a feed move before any feed: {line}");
        moves.push((code != 0, position));
    }
    moves
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn fanuc_and_haas_programs_pass_rs274_with_the_linuxcnc_moves() {
    let app = app().await;
    for (name, endpoint, body, want) in linuxcnc_moves(&app).await {
        for dialect in ["fanuc", "haas"] {
            let text = program(&app, &endpoint, &body, dialect).await;
            let label = format!("{name}_{dialect}");
            let digits = if dialect == "haas" { 5 } else { 4 };
            let number = text.lines().nth(1).and_then(|l| l.strip_prefix('O')).and_then(|l| l.split(' ').next());
            assert_eq!(number.map(str::len), Some(digits), "{label}: {text}");
            let got = rs274_moves(&text, app.directory(), &label).expect("rs274 present");
            assert_same_moves(&label, &got, &want);
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
#[cfg_attr(
    not(kerf_has_nc_gcode_interpreter),
    ignore = "nc-gcode-interpreter not found: pip install -r tests/requirements.txt"
)]
async fn sinumerik_programs_read_by_nc_gcode_interpreter_move_as_linuxcnc() {
    let app = app().await;
    for (name, endpoint, body, want) in linuxcnc_moves(&app).await {
        let text = program(&app, &endpoint, &body, "sinumerik").await;
        let label = format!("{name}_sinumerik");
        let tool_call = text.contains(" D1\nM6\n") || text.contains("\nM0\n");
        assert!(text.starts_with("; ") && text.contains("\nG642\n") && tool_call, "{label}: {text}");
        assert!(text.ends_with("M30\n"), "{label}");
        assert!(!text.contains('('), "{label}: Siemens comments start with ;");
        let got = moves_of(&python(SINUMERIK, &text, &label));
        assert_same_moves(&label, &got, &want);
    }
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
#[cfg_attr(not(kerf_has_pygcode), ignore = "pygcode not found: pip install -r tests/requirements.txt")]
async fn grbl_programs_read_by_pygcode_move_as_linuxcnc() {
    let app = app().await;
    for (name, endpoint, body, want) in linuxcnc_moves(&app).await {
        let text = program(&app, &endpoint, &body, "grbl").await;
        let label = format!("{name}_grbl");
        check_grbl_words(&label, &text);
        assert!(!text.contains("G43") && !text.contains("M6") && text.contains("\nM0\n"), "{label}: {text}");
        let got = moves_of(&python(GRBL, &text, &label));
        assert_same_moves(&label, &got, &want);
    }
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn heidenhain_programs_read_well_formed_with_the_linuxcnc_moves() {
    let app = app().await;
    for (name, endpoint, body, want) in linuxcnc_moves(&app).await {
        let klartext = program(&app, &endpoint, &body, "heidenhain").await;
        let got = read_klartext(&format!("{name}_heidenhain"), &klartext);
        assert_moves_among(&format!("{name}_heidenhain"), &got, &want);
        let iso = program(&app, &endpoint, &body, "heidenhain_iso").await;
        let got = read_heidenhain_iso(&format!("{name}_heidenhain_iso"), &iso);
        assert_moves_among(&format!("{name}_heidenhain_iso"), &got, &want);
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn a_machine_names_its_post_and_an_unknown_post_is_refused() {
    let app = app().await;
    let machine = json!({"block_time_ms": 4, "max_feed": 6000, "dialect": "heidenhain"});
    let response = app.put_json("/api/v1/machines/tnc", &machine).await;
    assert!(response.status().is_success(), "{}", response.status());
    let stored = json_with(app.get("/api/v1/machines/tnc").await, 200).await;
    assert_eq!(stored["dialect"], "heidenhain");
    let mut body = kerf_cases::deburr::tube_request();
    body["machine"] = json!("tnc");
    let text = program(&app, "deburr", &body, "heidenhain").await;
    let url = app.url("/api/v1/deburr?format=gcode");
    let from_machine = app.client.post(url).json(&body).send().await.unwrap().text().await.unwrap();
    assert_eq!(from_machine, text, "the machine's post writes the program");
    assert!(text.starts_with("0 BEGIN PGM "), "{text}");
    let url = app.url("/api/v1/deburr?format=gcode&dialect=mazak");
    let response = app.client.post(url).json(&body).send().await.unwrap();
    assert_eq!(response.status(), 400);
    let bad = json!({"block_time_ms": 4, "max_feed": 6000, "dialect": "mazak"});
    let status = app.put_json("/api/v1/machines/bad", &bad).await.status();
    assert!(status.is_client_error(), "{status}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
#[cfg_attr(
    not(kerf_has_nc_gcode_interpreter),
    ignore = "nc-gcode-interpreter not found: pip install -r tests/requirements.txt"
)]
async fn sinumerik_calls_a_named_tool_by_name_and_programs_download_under_their_posts_names() {
    let app = app().await;
    app.register_tool(9, &json!({"kind": "flat", "radius": 3, "flutes": 3, "name": "Flat \"6\" end mill, long reach"}))
        .await;
    let mut body = kerf_cases::contour::arrow_request(1);
    body["tool"] = json!(9);
    let sinumerik = program(&app, "contour", &body, "sinumerik").await;
    assert!(sinumerik.contains("\nT=\"FLAT  6  END MILL, LONG REACH\" D1 ; T9\nM6\nG0 Z"), "{sinumerik}");
    let fanuc = program(&app, "contour", &body, "fanuc").await;
    assert!(fanuc.contains("\nT9 M06\nG00 G43 H9 Z"), "{fanuc}");
    let linuxcnc = program(&app, "contour", &body, "linuxcnc").await;
    let want = rs274_moves(&linuxcnc, app.directory(), "named_linuxcnc").expect("rs274 present");
    let got = moves_of(&python(SINUMERIK, &sinumerik, "named_sinumerik"));
    assert_same_moves("named_sinumerik", &got, &want);

    for (dialect, extension) in [
        ("fanuc", "nc"),
        ("haas", "nc"),
        ("linuxcnc", "nc"),
        ("grbl", "nc"),
        ("sinumerik", "mpf"),
        ("heidenhain", "h"),
        ("heidenhain_iso", "i"),
    ] {
        for _ in 0..2 {
            // The second answer comes from the answer cache: the same name.
            let url = app.url(&format!("/api/v1/contour?format=gcode&dialect={dialect}"));
            let response = app.client.post(url).json(&body).send().await.unwrap();
            assert_eq!(response.status(), 200);
            let disposition = response.headers()["content-disposition"].to_str().unwrap().to_owned();
            assert_eq!(disposition, format!("attachment; filename=\"kerf-contour.{extension}\""));
        }
    }
    let machine = json!({"block_time_ms": 4, "max_feed": 6000, "dialect": "sinumerik"});
    assert!(app.put_json("/api/v1/machines/840d", &machine).await.status().is_success());
    body["machine"] = json!("840d");
    let response = app.client.post(app.url("/api/v1/contour?format=gcode")).json(&body).send().await.unwrap();
    assert_eq!(response.headers()["content-disposition"], "attachment; filename=\"kerf-contour.mpf\"");
    let json = app.client.post(app.url("/api/v1/contour")).json(&body).send().await.unwrap();
    assert!(json.headers().get("content-disposition").is_none(), "the JSON answer is not a download");
}
