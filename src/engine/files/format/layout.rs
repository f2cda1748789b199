//! The layout of spherecal's JSON files in one pass: serde_json's pretty
//! printing, except that a container whose entries are all scalars goes
//! on one line (arrays always: `[y, z]`, a matrix row, joint readings;
//! objects when the line stays within [`MAX_LINE`] bytes:
//! `{"alpha": 0.0, "a": 0.0, …}`), as FORMAT.md shows them.
//!
//! A [`serde_json::ser::Formatter`] that holds each open container's
//! entries until it knows whether one of them is itself a container; the
//! text is written once, with no pretty intermediate and no pass over its
//! lines, so a session of millions of stripe points costs its own size.

use std::io;

use serde_json::ser::{CharEscape, CompactFormatter, Formatter};

/// Longest line a one-line object may make, indent and a following comma
/// included.
pub(super) const MAX_LINE: usize = 120;

/// An open container.
#[derive(Default)]
struct Frame {
    /// `[` (else `{`).
    array: bool,
    /// Nesting depth: its entries are indented `2 × level` spaces.
    level: usize,
    /// Still only scalar entries: they are held in `text`.
    flat: bool,
    /// A flat frame's entries so far, joined by `, ` (the one-line form
    /// without its brackets), the entry in progress last.
    text: Vec<u8>,
    /// Where each entry of `text` starts (the one in progress included).
    starts: Vec<usize>,
    /// Entries written, in a pretty frame.
    written: usize,
}

impl Frame {
    /// The entries of a flat frame, the one in progress included.
    fn entries(&self) -> impl Iterator<Item = &[u8]> {
        let ends = self
            .starts
            .iter()
            .skip(1)
            .map(|&s| s - 2)
            .chain(std::iter::once(self.text.len()));
        self.starts.iter().zip(ends).map(|(&a, b)| &self.text[a..b])
    }

    /// The pretty form of a flat frame's entries: each on its own line.
    fn pretty_entries(&self, out: &mut Vec<u8>) {
        for (k, e) in self.entries().enumerate() {
            out.extend_from_slice(if k == 0 { b"\n" } else { b",\n" });
            indent(out, self.level);
            out.extend_from_slice(e);
        }
    }
}

/// The formatter (see the module doc).
#[derive(Default)]
pub(super) struct Layout {
    /// Open containers are `frames[..depth]`; the frames beyond are kept
    /// for their buffers.
    frames: Vec<Frame>,
    depth: usize,
    /// A one-line object exactly [`MAX_LINE`] bytes long: one line unless a
    /// comma follows it. `(one line, pretty form)`.
    pending: Option<(Vec<u8>, Vec<u8>)>,
    /// Bytes written since the last line break.
    line: usize,
    /// A scalar on its way to the output.
    scratch: Vec<u8>,
}

fn indent(out: &mut Vec<u8>, level: usize) {
    out.extend(std::iter::repeat_n(b' ', 2 * level));
}

impl Layout {
    fn top(&mut self) -> Option<&mut Frame> {
        self.depth.checked_sub(1).map(|d| &mut self.frames[d])
    }

    /// Writes `bytes` to the output, keeping count of the line's length.
    fn emit<W: ?Sized + io::Write>(&mut self, w: &mut W, bytes: &[u8]) -> io::Result<()> {
        match bytes.iter().rposition(|&b| b == b'\n') {
            Some(i) => self.line = bytes.len() - i - 1,
            None => self.line += bytes.len(),
        }
        w.write_all(bytes)
    }

    /// Writes `bytes` into the open flat entry, or to the output.
    fn put<W: ?Sized + io::Write>(&mut self, w: &mut W, bytes: &[u8]) -> io::Result<()> {
        match self.top() {
            Some(f) if f.flat => {
                f.text.extend_from_slice(bytes);
                Ok(())
            }
            _ => self.emit(w, bytes),
        }
    }

    /// A pending object, now that it is known whether a comma follows.
    fn resolve<W: ?Sized + io::Write>(&mut self, w: &mut W, comma: bool) -> io::Result<()> {
        match self.pending.take() {
            Some((one, pretty)) => self.emit(w, if comma { &pretty } else { &one }),
            None => Ok(()),
        }
    }

    /// A container starts: every flat frame holding it is written out in
    /// pretty form (from the outermost), its entry in progress last.
    fn unflatten<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        for i in 0..self.depth {
            if !self.frames[i].flat {
                continue;
            }
            let f = &mut self.frames[i];
            f.flat = false;
            let mut text = vec![if f.array { b'[' } else { b'{' }];
            f.pretty_entries(&mut text);
            f.written = f.starts.len();
            self.emit(w, &text)?;
        }
        Ok(())
    }

    fn begin<W: ?Sized + io::Write>(&mut self, w: &mut W, array: bool) -> io::Result<()> {
        self.unflatten(w)?;
        if self.frames.len() == self.depth {
            self.frames.push(Frame::default());
        }
        self.depth += 1;
        let level = self.depth;
        let f = &mut self.frames[level - 1];
        f.array = array;
        f.level = level;
        f.flat = true;
        f.text.clear();
        f.starts.clear();
        f.written = 0;
        Ok(())
    }

    fn entry<W: ?Sized + io::Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        if !first {
            self.resolve(w, true)?;
        }
        let Some(f) = self.top() else {
            return Ok(());
        };
        if f.flat {
            if !first {
                f.text.extend_from_slice(b", ");
            }
            f.starts.push(f.text.len());
            return Ok(());
        }
        f.written += 1;
        let level = f.level;
        let mut text = std::mem::take(&mut self.scratch);
        text.clear();
        text.extend_from_slice(if first { b"\n" } else { b",\n" });
        indent(&mut text, level);
        let done = self.emit(w, &text);
        self.scratch = text;
        done
    }

    fn end<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.resolve(w, false)?;
        let Some(d) = self.depth.checked_sub(1) else {
            return Ok(());
        };
        self.depth = d;
        let f = std::mem::take(&mut self.frames[d]);
        let done = self.close(w, &f);
        self.frames[d] = f;
        done
    }

    /// Writes the end of the closed frame `f`.
    fn close<W: ?Sized + io::Write>(&mut self, w: &mut W, f: &Frame) -> io::Result<()> {
        let (open, close) = if f.array { (b'[', b']') } else { (b'{', b'}') };
        if !f.flat {
            let mut text = Vec::new();
            if f.written > 0 {
                text.push(b'\n');
                indent(&mut text, f.level - 1);
            }
            text.push(close);
            return self.emit(w, &text);
        }
        let mut one = std::mem::take(&mut self.scratch);
        one.clear();
        one.push(open);
        one.extend_from_slice(&f.text);
        one.push(close);
        let length = self.line + one.len();
        let done = if f.array
            || f.starts.is_empty()
            || length < MAX_LINE
            || (length == MAX_LINE && self.depth == 0)
        {
            // Arrays always; an object within the line (at the top level
            // no comma can follow).
            self.put(w, &one)
        } else {
            // An object's parent holds a container, so it is written out:
            // the line so far is `self.line`.
            let mut pretty = vec![open];
            f.pretty_entries(&mut pretty);
            pretty.push(b'\n');
            indent(&mut pretty, f.level - 1);
            pretty.push(close);
            if length == MAX_LINE {
                self.pending = Some((one.clone(), pretty));
                Ok(())
            } else {
                self.put(w, &pretty)
            }
        };
        self.scratch = one;
        done
    }
}

/// A scalar written by serde_json's compact formatter, routed by [`Layout::put`].
macro_rules! scalar {
    ($($name:ident($($arg:ident: $ty:ty),*);)*) => {
        $(
            fn $name<W: ?Sized + io::Write>(&mut self, w: &mut W $(, $arg: $ty)*) -> io::Result<()> {
                match self.top() {
                    Some(f) if f.flat => CompactFormatter.$name(&mut f.text $(, $arg)*),
                    _ => {
                        let mut buf = std::mem::take(&mut self.scratch);
                        buf.clear();
                        CompactFormatter.$name(&mut buf $(, $arg)*)?;
                        let done = self.emit(w, &buf);
                        self.scratch = buf;
                        done
                    }
                }
            }
        )*
    };
}

impl Formatter for Layout {
    scalar! {
        write_null();
        write_bool(value: bool);
        write_i8(value: i8);
        write_i16(value: i16);
        write_i32(value: i32);
        write_i64(value: i64);
        write_i128(value: i128);
        write_u8(value: u8);
        write_u16(value: u16);
        write_u32(value: u32);
        write_u64(value: u64);
        write_u128(value: u128);
        write_f32(value: f32);
        write_f64(value: f64);
        write_number_str(value: &str);
        begin_string();
        end_string();
        write_string_fragment(fragment: &str);
        write_char_escape(char_escape: CharEscape);
        write_byte_array(value: &[u8]);
        write_raw_fragment(fragment: &str);
    }

    fn begin_array<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.begin(w, true)
    }

    fn end_array<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.end(w)
    }

    fn begin_array_value<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.entry(w, first)
    }

    fn end_array_value<W: ?Sized + io::Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }

    fn begin_object<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.begin(w, false)
    }

    fn end_object<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.end(w)
    }

    fn begin_object_key<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.entry(w, first)
    }

    fn end_object_key<W: ?Sized + io::Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }

    fn begin_object_value<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.put(w, b": ")
    }

    fn end_object_value<W: ?Sized + io::Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }
}
