//! The line numbers of a program's verification warnings in the program's own post (docs/spec/
//! verify.md §9.3). A capability's verification cuts its Fanuc program, so the warnings in the
//! header name Fanuc lines; another post numbers the same moves otherwise (a heading without `%`,
//! Haas's `G187` line, an arc's centre block, a helix as chords, Klartext's blocks), and a
//! program's comments must name its own lines. The moves of the two programs are matched by their
//! end points, in order.

use std::collections::HashMap;

/// What precedes a line number in a warning comment (the posts write comments in capitals).
const AT_LINE: &str = " AT LINE ";

/// How many moves of the program are looked through for the one a verified move matches: more
/// than a helix the Fanuc program writes as one arc and Heidenhain ISO as chords.
const WINDOW: usize = 100_000;

/// Most end points compared in all (tens of milliseconds): programs that do not match move for
/// move (another engagement candidate's) give up rather than search on.
const COMPARISONS: usize = 50_000_000;

/// A motion block's end point as printed (an axis the program has not yet set: `None`).
type End = [Option<f64>; 3];

/// `program` with the line of every `AT LINE n` in its header's comments (before its first
/// motion) taken from `verified` (the Fanuc program the verification cut, same moves) to the line
/// of the same move in `program`; a reference to a move `program` does not have is left out
/// (the comment keeps the position).
pub(crate) fn warnings_in_own_lines(program: String, verified: &str) -> String {
    let first_motion = motions(&program).first().map_or(usize::MAX, |(line, _)| *line);
    let lines: Vec<&str> = program.lines().collect();
    let referenced: Vec<usize> =
        lines.iter().take(first_motion.saturating_sub(1)).filter_map(|line| referenced_line(line)).collect();
    let Some(&last) = referenced.iter().max() else { return program };
    let map = line_map(verified, &program, last);
    let header_end = lines.iter().take(first_motion.saturating_sub(1)).map(|line| line.len() + 1).sum::<usize>();
    let header_end = header_end.min(program.len());
    let mut out = restate_warnings(&program[..header_end], |line| map.get(&line).copied());
    out.push_str(&program[header_end..]);
    out
}

/// `lines` (a program's comments) with the line of every warning's `AT LINE n` restated as
/// `restate(n)`; a line it has none for is left out (the comment keeps its position).
pub(crate) fn restate_warnings(lines: &str, restate: impl Fn(usize) -> Option<usize>) -> String {
    let mut out = String::with_capacity(lines.len());
    for line in lines.split_inclusive('\n') {
        let Some(number) = referenced_line(line) else {
            out.push_str(line);
            continue;
        };
        let at = line.find(AT_LINE).unwrap_or(0);
        let digits = line[at + AT_LINE.len()..].bytes().take_while(u8::is_ascii_digit).count();
        out.push_str(&line[..at]);
        if let Some(own) = restate(number) {
            out.push_str(AT_LINE);
            out.push_str(&own.to_string());
        }
        out.push_str(&line[at + AT_LINE.len() + digits..]);
    }
    out
}

/// The line number a warning comment refers to.
fn referenced_line(line: &str) -> Option<usize> {
    if !line.contains("WARNING") {
        return None;
    }
    let after = &line[line.find(AT_LINE)? + AT_LINE.len()..];
    let digits = after.bytes().take_while(u8::is_ascii_digit).count();
    after[..digits].parse().ok()
}

/// For the motion lines of `verified` up to line `last`, the line of `program` with the same move:
/// matched in order by end point; a verified move without its own match (a chord of an arc
/// `program` writes whole) goes with the next move matched.
fn line_map(verified: &str, program: &str, last: usize) -> HashMap<usize, usize> {
    let theirs = motions(program);
    let mut map = HashMap::new();
    let mut pending = Vec::new();
    let mut next = 0;
    let mut budget = COMPARISONS;
    for (line, end) in motions(verified) {
        if line > last && pending.is_empty() {
            break;
        }
        pending.push(line);
        let ahead = &theirs[next.min(theirs.len())..];
        let found = ahead.iter().take(WINDOW.min(budget)).position(|(_, their)| same(their, &end));
        budget = budget.saturating_sub(found.map_or(WINDOW.min(ahead.len()), |offset| offset + 1));
        if budget == 0 {
            break;
        }
        if let Some(offset) = found {
            let own = theirs[next + offset].0;
            for line in pending.drain(..) {
                map.insert(line, own);
            }
            next += offset + 1;
        }
    }
    map
}

/// Whether two printed end points are the same point.
fn same(a: &End, b: &End) -> bool {
    a.iter().zip(b).all(|pair| match pair {
        (Some(a), Some(b)) => (a - b).abs() <= 1e-6 * a.abs().max(1.0),
        (None, None) => true,
        _ => false,
    })
}

/// Every motion block of a program kerf wrote, in any post, with its line (1-based) and end point.
fn motions(program: &str) -> Vec<(usize, End)> {
    let mut at: End = [None; 3];
    let mut found = Vec::new();
    for (index, line) in program.lines().enumerate() {
        let mut words = without_number(line.trim()).split_ascii_whitespace();
        let Some(first) = words.next() else { continue };
        if !matches!(first, "G0" | "G00" | "G1" | "G01" | "G2" | "G02" | "G3" | "G03" | "L" | "C") {
            continue;
        }
        for word in words {
            let axis = match word.as_bytes().first() {
                Some(b'X') => 0,
                Some(b'Y') => 1,
                Some(b'Z') => 2,
                _ => continue,
            };
            if let Ok(value) = word[1..].parse::<f64>() {
                at[axis] = Some(value);
            }
        }
        found.push((index + 1, at));
    }
    found
}

/// A block without its line number (`N70 …`, Klartext's `7 …`).
fn without_number(line: &str) -> &str {
    let digits = line.strip_prefix('N').unwrap_or(line);
    let count = digits.bytes().take_while(u8::is_ascii_digit).count();
    if count > 0 && digits[count..].starts_with(' ') { &digits[count + 1..] } else { line }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FANUC: &str = "%\nO1000 (KERF)\n(WARNING HOLDER CONTACT AT LINE 8: 0.500 MM DEEP AT X0.250 Y9.250 Z-0.500)\n\
        (WARNING GOUGE AT LINE 10: 0.200 MM DEEP AT X3 Y0 Z-1)\nG21 G17 G90\nT1 M06\nG00 Z5.0000\n\
        G00 X-10.0000 Y0.0000 Z5.0000\nG01 X-10.0000 Y0.0000 Z-2.0000 F150\nG01 X10.0000 Y0.0000 Z-2.0000\n\
        G00 Z5.0000\nM30\n%\n";

    #[test]
    fn references_move_to_the_same_moves_in_another_post() {
        // Grbl: no `%` lines, so every move is a line earlier.
        let grbl = "(KERF)\n(WARNING HOLDER CONTACT AT LINE 8: 0.500 MM DEEP AT X0.250 Y9.250 Z-0.500)\n\
            (WARNING GOUGE AT LINE 10: 0.200 MM DEEP AT X3 Y0 Z-1)\nG21 G17 G90\nM0\nG0 Z5.0000\n\
            G0 X-10.0000 Y0.0000 Z5.0000\nG1 X-10.0000 Y0.0000 Z-2.0000 F150\nG1 X10.0000 Y0.0000 Z-2.0000\nG0 Z5.0000\nM30\n";
        let renumbered = warnings_in_own_lines(grbl.to_owned(), FANUC);
        let lines: Vec<&str> = renumbered.lines().collect();
        assert!(lines[1].contains("AT LINE 7: ") && lines[2].contains("AT LINE 9: "), "{renumbered}");
        assert!(lines[6].starts_with("G0 X-10") && lines[8].starts_with("G1 X10"), "{renumbered}");
        // The rest is untouched, the last newline kept.
        assert_eq!(renumbered.replace("LINE 7:", "LINE 8:").replace("LINE 9:", "LINE 10:"), grbl);
    }

    #[test]
    fn numbered_blocks_and_signed_words_are_read() {
        let iso = "%KERF1000 G71 *\nN10 ; KERF *\nN20 ; WARNING GOUGE AT LINE 10: 0.200 MM DEEP *\n\
            N30 G17 G40 G90 *\nN40 T1 G17 *\nN50 G00 Z+5.0000 *\nN60 G00 X-10.0000 Y+0.0000 Z+5.0000 *\n\
            N70 G01 X-10.0000 Y+0.0000 Z-2.0000 F150 *\nN80 G01 X+10.0000 Y+0.0000 Z-2.0000 *\nN90 M30 *\n";
        let renumbered = warnings_in_own_lines(iso.to_owned(), FANUC);
        assert!(renumbered.lines().nth(2).unwrap().contains("AT LINE 9: "), "{renumbered}");
    }

    #[test]
    fn a_move_the_program_does_not_have_loses_its_line_not_its_position() {
        let other =
            "(KERF)\n(WARNING GOUGE AT LINE 10: 0.200 MM DEEP AT X3 Y0 Z-1)\nG0 X50.0000 Y50.0000 Z5.0000\nM30\n";
        let renumbered = warnings_in_own_lines(other.to_owned(), FANUC);
        assert_eq!(renumbered.lines().nth(1).unwrap(), "(WARNING GOUGE: 0.200 MM DEEP AT X3 Y0 Z-1)");
    }

    #[test]
    fn chords_of_an_arc_written_whole_go_with_the_arc() {
        let chords = "(WARNING GOUGE AT LINE 4: 0.2 MM DEEP)\nG00 X0.0000 Y0.0000 Z5.0000\nG01 X0.0000 Y0.0000 Z-1.0000\n\
            G01 X1.0000 Y1.0000 Z-1.0000\nG01 X2.0000 Y0.0000 Z-1.0000\nM30\n";
        let arc = "(KERF)\n(WARNING GOUGE AT LINE 4: 0.2 MM DEEP)\nG00 X0.0000 Y0.0000 Z5.0000\nG01 X0.0000 Y0.0000 Z-1.0000\n\
            G02 X2.0000 Y0.0000 Z-1.0000 I1.0000 J0.0000\nM30\n";
        let renumbered = warnings_in_own_lines(arc.to_owned(), chords);
        assert!(renumbered.lines().nth(1).unwrap().contains("AT LINE 5: "), "{renumbered}");
    }
}
