//! Memory images: one [`Image`] per memory of the design, written as `$readmemh` hex (one word
//! per line, ⌈width/4⌉ hex digits, address 0 first) and as Intel MIF (Quartus' Memory
//! Initialization File: `WIDTH`, `DEPTH`, `ADDRESS_RADIX=UNS`, `DATA_RADIX=HEX`, one
//! `address : word;` line per word), and read back from either ([`Image::parse_hex`],
//! [`Image::parse_mif`]) so that a test can check that the files reproduce the machine program.

use std::fmt::Write;

/// The words of one memory, address 0 first, each `width` bits (≤ 64) wide.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// File stem (`pe0_instr`): the files are `hex/STEM.hex` and `mif/STEM.mif`.
    pub name: String,
    /// Bits per word (1..=64).
    pub width: u32,
    /// The words; a word never has bits at or above `width`.
    pub words: Vec<u64>,
}

/// Why an image file does not read back.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct ImageError {
    /// 1-based line of the file.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

fn err(line: usize, message: impl Into<String>) -> ImageError {
    ImageError { line, message: message.into() }
}

impl Image {
    /// Hex digits per word in the hex file and the MIF.
    pub fn digits(&self) -> usize {
        self.width.div_ceil(4).max(1) as usize
    }

    /// Size in bits (`width × words`).
    pub fn bits(&self) -> u64 {
        u64::from(self.width) * self.words.len() as u64
    }

    /// The `$readmemh` text: one word per line, zero-padded hex, address 0 first. An empty image
    /// gets one zero word (a Verilog memory has at least one word).
    pub fn to_hex(&self) -> String {
        let mut s = String::with_capacity((self.digits() + 1) * self.words.len().max(1));
        for w in self.words_or_zero() {
            let _ = writeln!(s, "{w:0d$x}", d = self.digits());
        }
        s
    }

    /// The Intel MIF text (Quartus "Memory Initialization File"), same words as [`Image::to_hex`].
    pub fn to_mif(&self) -> String {
        let words = self.words_or_zero();
        let mut s = String::with_capacity(16 * words.len() + 128);
        let _ = writeln!(s, "-- robovec codegen<fpga>: {}", self.name);
        let _ = writeln!(s, "WIDTH={};", self.width);
        let _ = writeln!(s, "DEPTH={};", words.len());
        s += "ADDRESS_RADIX=UNS;\nDATA_RADIX=HEX;\nCONTENT BEGIN\n";
        for (a, w) in words.iter().enumerate() {
            let _ = writeln!(s, "\t{a} : {w:0d$x};", d = self.digits());
        }
        s += "END;\n";
        s
    }

    fn words_or_zero(&self) -> Vec<u64> {
        if self.words.is_empty() {
            vec![0]
        } else {
            self.words.clone()
        }
    }

    /// Reads a `$readmemh` file of `width`-bit words: whitespace-separated hex words, `//`
    /// comments, `@ADDR` address jumps (words not given are 0).
    ///
    /// # Errors
    /// [`ImageError`] naming the line of a word that is not hex or is wider than `width`.
    pub fn parse_hex(name: &str, width: u32, text: &str) -> Result<Image, ImageError> {
        let mut words: Vec<u64> = Vec::new();
        let mut at = 0usize;
        for (i, line) in text.lines().enumerate() {
            let line = line.split("//").next().unwrap_or("");
            for tok in line.split_whitespace() {
                if let Some(a) = tok.strip_prefix('@') {
                    at = usize::from_str_radix(a, 16).map_err(|_| err(i + 1, format!("bad address `{tok}`")))?;
                    continue;
                }
                let w = parse_word(tok, width).map_err(|m| err(i + 1, m))?;
                if words.len() <= at {
                    words.resize(at + 1, 0);
                }
                words[at] = w;
                at += 1;
            }
        }
        Ok(Image { name: name.into(), width, words })
    }

    /// Reads an Intel MIF with `DATA_RADIX=HEX` and `ADDRESS_RADIX` `UNS`, `DEC` or `HEX`:
    /// `a : w;` and `[a..b] : w;` lines, `--` comments; `WIDTH` and `DEPTH` must be given.
    ///
    /// # Errors
    /// [`ImageError`] for a missing `WIDTH`/`DEPTH`, another radix, a malformed content line, an
    /// address beyond `DEPTH` or a word wider than `WIDTH`.
    pub fn parse_mif(name: &str, text: &str) -> Result<Image, ImageError> {
        let (mut width, mut depth, mut addr_radix) = (None, None, 10);
        let mut words: Vec<u64> = Vec::new();
        let mut content = false;
        for (i, raw) in text.lines().enumerate() {
            let n = i + 1;
            let line = raw.split("--").next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let upper = line.to_ascii_uppercase();
            if !content {
                if upper.starts_with("CONTENT") {
                    let (Some(w), Some(d)) = (width, depth) else {
                        return Err(err(n, "CONTENT before WIDTH and DEPTH"));
                    };
                    words = vec![0; d];
                    content = true;
                    let _ = w;
                    continue;
                }
                let (k, v) =
                    upper.trim_end_matches(';').split_once('=').ok_or_else(|| err(n, "expected KEY=VALUE;"))?;
                let v = v.trim();
                match k.trim() {
                    "WIDTH" => width = Some(v.parse::<u32>().map_err(|_| err(n, "bad WIDTH"))?),
                    "DEPTH" => depth = Some(v.parse::<usize>().map_err(|_| err(n, "bad DEPTH"))?),
                    "ADDRESS_RADIX" => {
                        addr_radix = match v {
                            "UNS" | "DEC" => 10,
                            "HEX" => 16,
                            _ => return Err(err(n, format!("ADDRESS_RADIX {v} not supported"))),
                        }
                    }
                    "DATA_RADIX" if v == "HEX" => {}
                    "DATA_RADIX" => return Err(err(n, format!("DATA_RADIX {v} not supported (HEX only)"))),
                    other => return Err(err(n, format!("unknown key `{other}`"))),
                }
                continue;
            }
            if upper.starts_with("END") {
                let width = width.unwrap_or(0);
                return Ok(Image { name: name.into(), width, words });
            }
            let (a, w) =
                line.trim_end_matches(';').split_once(':').ok_or_else(|| err(n, "expected `ADDRESS : WORD;`"))?;
            let word = parse_word(w.trim(), width.unwrap_or(64)).map_err(|m| err(n, m))?;
            let a = a.trim();
            let range = match a.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
                Some(r) => {
                    let (lo, hi) = r.split_once("..").ok_or_else(|| err(n, "expected [A..B]"))?;
                    (parse_addr(lo, addr_radix, n)?, parse_addr(hi, addr_radix, n)?)
                }
                None => {
                    let x = parse_addr(a, addr_radix, n)?;
                    (x, x)
                }
            };
            if range.1 >= words.len() || range.0 > range.1 {
                return Err(err(n, format!("address {a} outside DEPTH {}", words.len())));
            }
            words[range.0..=range.1].fill(word);
        }
        Err(err(text.lines().count(), "missing END;"))
    }
}

fn parse_addr(s: &str, radix: u32, line: usize) -> Result<usize, ImageError> {
    usize::from_str_radix(s.trim(), radix).map_err(|_| err(line, format!("bad address `{}`", s.trim())))
}

fn parse_word(tok: &str, width: u32) -> Result<u64, String> {
    let w = u64::from_str_radix(tok, 16).map_err(|_| format!("`{tok}` is not a hex word"))?;
    if width < 64 && w >> width != 0 {
        return Err(format!("`{tok}` is wider than {width} bits"));
    }
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(width: u32, words: &[u64]) -> Image {
        Image { name: "t".into(), width, words: words.to_vec() }
    }

    #[test]
    fn hex_is_one_padded_word_per_line_and_reads_back() {
        let i = img(52, &[0, 0xf_ffff_ffff_ffff, 0x123]);
        assert_eq!(i.to_hex(), "0000000000000\nfffffffffffff\n0000000000123\n");
        assert_eq!(Image::parse_hex("t", 52, &i.to_hex()).unwrap(), i);
        // iverilog's $writememh adds address comments; @ jumps fill with zeros
        let got = Image::parse_hex("t", 8, "// 0x00000000\n0a\n@3 ff\n").unwrap();
        assert_eq!(got.words, vec![0x0a, 0, 0, 0xff]);
        assert_eq!(Image::parse_hex("t", 4, "1f\n").unwrap_err().line, 1);
    }

    #[test]
    fn mif_has_quartus_header_and_reads_back() {
        let i = img(6, &[0x3f, 0x01]);
        assert_eq!(
            i.to_mif(),
            "-- robovec codegen<fpga>: t\nWIDTH=6;\nDEPTH=2;\nADDRESS_RADIX=UNS;\nDATA_RADIX=HEX;\nCONTENT BEGIN\n\t0 : 3f;\n\t1 : 01;\nEND;\n"
        );
        assert_eq!(Image::parse_mif("t", &i.to_mif()).unwrap(), i);
        let ranged =
            "WIDTH=8;\nDEPTH=4;\nADDRESS_RADIX=HEX;\nDATA_RADIX=HEX;\nCONTENT BEGIN\n[0..2] : 7;\n3 : a;\nEND;\n";
        assert_eq!(Image::parse_mif("t", ranged).unwrap().words, vec![7, 7, 7, 10]);
        assert!(Image::parse_mif("t", "WIDTH=8;\nDEPTH=1;\nDATA_RADIX=BIN;\n").is_err());
    }
}
