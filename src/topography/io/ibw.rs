//! Igor binary wave (`.ibw`), as Asylum Research AFMs write it (WaveMetrics technical note
//! TN003).
//!
//! A binary header and a wave header, guarded by a checksum (the 16-bit words of both sum to
//! zero), then the wave data, then optional blocks (formula, note, extended units, dimension
//! labels). The byte order is that of the machine that wrote it: the version number, which is
//! small, tells it. Version 5 waves have up to four dimensions: an AFM image is
//! `nx × ny × channels`, stored column-major (x fastest), its channels named by the labels of
//! the third dimension. Versions 1–3 hold a single profile, read as one line.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::quantity::metres_per;

pub struct Ibw;

/// Bytes of a dimension label (MAX_DIM_LABEL_CHARS + 1).
const LABEL_BYTES: usize = 32;

/// Size of the binary header of each version (0 = unknown version) and of the wave header.
fn header_sizes(version: i16) -> Option<(usize, usize)> {
    match version {
        1 => Some((8, 110)),
        2 => Some((16, 110)),
        3 => Some((20, 110)),
        5 => Some((64, 320)),
        _ => None,
    }
}

/// Byte order and version, from the version field that is small in the right byte order.
fn version(bytes: &[u8]) -> Option<(Endian, i16)> {
    let b: [u8; 2] = bytes.get(..2)?.try_into().ok()?;
    [(Endian::Little, i16::from_le_bytes(b)), (Endian::Big, i16::from_be_bytes(b))]
        .into_iter()
        .find(|&(_, v)| header_sizes(v).is_some())
}

/// Whether the 16-bit words of both headers sum to zero, as Igor writes them.
fn checksum_ok(bytes: &[u8], endian: Endian, len: usize) -> bool {
    bytes.get(..len).is_some_and(|h| {
        let sum = h.chunks_exact(2).fold(0u16, |s, w| {
            let w = [w[0], w[1]];
            s.wrapping_add(if endian == Endian::Little { u16::from_le_bytes(w) } else { u16::from_be_bytes(w) })
        });
        sum == 0
    })
}

impl Format for Ibw {
    fn name(&self) -> &'static str {
        "ibw"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["ibw"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        version(head)
            .is_some_and(|(endian, v)| header_sizes(v).is_some_and(|(bin, wave)| checksum_ok(head, endian, bin + wave)))
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// Every channel of the file; errors may quote the file's own (possibly corrupt) text.
fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let (endian, v) = version(bytes).ok_or("not an Igor binary wave: unknown version number")?;
    let (bin, wave) = header_sizes(v).ok_or("not an Igor binary wave: unknown version number")?;
    binary::extent(bytes, 0, bin + wave, "the Igor wave headers")?;
    if !checksum_ok(bytes, endian, bin + wave) {
        return Err("corrupt Igor binary wave: the header checksum does not match".into());
    }
    if v == 5 {
        read_v5(bytes, endian)
    } else {
        read_v1_3(bytes, endian, bin)
    }
}

/// The sample type of an Igor type code; complex and text waves are refused.
fn sample_type(code: i16) -> Result<Sample, String> {
    if code & 0x01 != 0 {
        return Err("complex Igor waves are not topographies".into());
    }
    Ok(match code {
        0x02 => Sample::F32,
        0x04 => Sample::F64,
        0x08 => Sample::I8,
        0x10 => Sample::I16,
        0x20 => Sample::I32,
        0x48 => Sample::U8,
        0x50 => Sample::U16,
        0x60 => Sample::U32,
        0 => return Err("text waves are not topographies".into()),
        c => return Err(format!("unknown Igor data type code {c:#x}")),
    })
}

/// Versions 1–3: one profile of `npnts` values, returned as a single line.
fn read_v1_3(bytes: &[u8], endian: Endian, bin: usize) -> Result<Vec<Channel>, String> {
    let mut c = Cursor::new(bytes, endian);
    c.skip(2, "version")?;
    let wfm_size = binary::non_negative(c.i32("wfmSize")?.into(), "wave size")?;
    let mut w = Cursor::new(&bytes[bin..], endian);
    let sample = sample_type(w.i16("type")?)?;
    w.skip(32, "wave header")?; // next, bname, whVersion, srcFldr, fileName
    let data_unit = binary::padded_str(w.take(4, "dataUnits")?);
    let x_unit = binary::padded_str(w.take(4, "xUnits")?);
    let n = binary::non_negative(w.i32("npnts")?.into(), "number of points")?;
    w.skip(2, "wave header")?;
    let dx = w.f64("hsA")?;
    let data_offset = bin + 110;
    let data_bytes = n.checked_mul(sample.size()).ok_or("the declared wave size overflows")?;
    if data_bytes > wfm_size {
        return Err(format!("corrupt Igor wave: {n} points do not fit the declared wave size {wfm_size}"));
    }
    let data = binary::grid(
        bytes,
        data_offset,
        (n, 1),
        Stored { sample, endian, bottom_first: false },
        "the wave data",
        |v| v,
    )?;
    let physical_size = physical_size_m((n as f64 * dx.abs(), &x_unit), (dx.abs(), &x_unit));
    Ok(vec![channel("no name (1)".into(), data, physical_size, &data_unit)])
}

fn read_v5(bytes: &[u8], endian: Endian) -> Result<Vec<Channel>, String> {
    let mut c = Cursor::new(bytes, endian);
    c.skip(4, "version and checksum")?;
    let mut size = |what: &str| -> Result<usize, String> { binary::non_negative(c.i32(what)?.into(), what) };
    let wfm_size = size("wfmSize")?;
    let formula_size = size("formulaSize")?;
    let note_size = size("noteSize")?;
    let data_e_units_size = size("dataEUnitsSize")?;
    let dim_e_units_size =
        [size("dimEUnitsSize")?, size("dimEUnitsSize")?, size("dimEUnitsSize")?, size("dimEUnitsSize")?];
    let dim_labels_size =
        [size("dimLabelsSize")?, size("dimLabelsSize")?, size("dimLabelsSize")?, size("dimLabelsSize")?];

    let mut w = Cursor::new(&bytes[64..], endian);
    w.skip(12, "wave header")?; // next, creationDate, modDate
    let npnts = binary::non_negative(w.i32("npnts")?.into(), "number of points")?;
    let sample = sample_type(w.i16("type")?)?;
    w.skip(68 - 18, "wave header")?; // dLock … dFolder
    let mut n_dim = [0usize; 4];
    for n in &mut n_dim {
        *n = binary::non_negative(w.i32("nDim")?.into(), "dimension size")?;
    }
    let sf_a = [w.f64("sfA")?, w.f64("sfA")?, w.f64("sfA")?, w.f64("sfA")?];
    w.skip(4 * 8, "sfB")?;
    let data_unit_field = binary::padded_str(w.take(4, "dataUnits")?);
    let dim_unit_fields = [
        binary::padded_str(w.take(4, "dimUnits")?),
        binary::padded_str(w.take(4, "dimUnits")?),
        binary::padded_str(w.take(4, "dimUnits")?),
        binary::padded_str(w.take(4, "dimUnits")?),
    ];

    if n_dim[3] != 0 {
        return Err("four-dimensional Igor waves are not topographies".into());
    }
    let (nx, ny, layers) = (n_dim[0], n_dim[1].max(1), n_dim[2].max(1));
    let per_layer = binary::grid_points(nx, ny)?;
    if per_layer.checked_mul(layers) != Some(npnts) {
        return Err(format!("corrupt Igor wave: {npnts} points do not match its dimensions {nx} x {ny} x {layers}"));
    }
    let data_bytes = npnts.checked_mul(sample.size()).ok_or("the declared wave size overflows")?;
    if wfm_size.checked_sub(320).is_none_or(|room| data_bytes > room) {
        return Err(format!("corrupt Igor wave: {npnts} points do not fit the declared wave size {wfm_size}"));
    }
    let data_offset = 64 + 320;

    // The optional blocks after the wave, in file order; each is checked before it is read.
    let mut at = 64usize.checked_add(wfm_size).ok_or("the declared wave size overflows")?;
    let mut block = |len: usize, what: &str| -> Result<&[u8], String> {
        let b = binary::extent(bytes, at, len, what)?;
        at += len;
        Ok(b)
    };
    block(formula_size, "the wave's formula")?;
    let note = binary::latin1(block(note_size, "the wave's note")?);
    let data_e_unit = binary::padded_str(block(data_e_units_size, "the extended data units")?);
    let mut dim_e_units = Vec::with_capacity(4);
    for len in dim_e_units_size {
        dim_e_units.push(binary::padded_str(block(len, "the extended dimension units")?));
    }
    let mut labels = Vec::with_capacity(4);
    for len in dim_labels_size {
        labels.push(block(len, "the dimension labels")?);
    }

    let prefer =
        |extended: &str, short: &str| if extended.is_empty() { short.to_string() } else { extended.to_string() };
    let data_unit = prefer(&data_e_unit, &data_unit_field);
    let (x_unit, y_unit) = (prefer(&dim_e_units[0], &dim_unit_fields[0]), prefer(&dim_e_units[1], &dim_unit_fields[1]));
    let physical_size = physical_size_m((nx as f64 * sf_a[0].abs(), &x_unit), (ny as f64 * sf_a[1].abs(), &y_unit));

    // Label 0 names the dimension itself, labels 1… its layers (the channels).
    let channel_labels: Vec<String> =
        labels[2].chunks_exact(LABEL_BYTES).skip(1).take(layers).map(binary::padded_str).collect();
    let note = parse_note(&note);
    let mut unnamed = 0;
    let mut channels = Vec::with_capacity(layers.min(channel_labels.len() + 1));
    for k in 0..layers {
        let label = channel_labels.get(k).filter(|l| !l.is_empty());
        let (name, unit) = match label {
            Some(l) if !note.is_empty() => (l.clone(), asylum_unit(l, &note).unwrap_or_default()),
            Some(l) => (l.clone(), data_unit.clone()),
            None => {
                unnamed += 1;
                (format!("no name ({unnamed})"), data_unit.clone())
            }
        };
        let offset = per_layer
            .checked_mul(sample.size())
            .and_then(|b| b.checked_mul(k))
            .and_then(|b| b.checked_add(data_offset))
            .ok_or("the declared wave size overflows")?;
        let data = binary::grid(
            bytes,
            offset,
            (nx, ny),
            // Igor's y axis points up: the last line is the top of the image.
            Stored { sample, endian, bottom_first: true },
            &format!("channel '{}'", binary::printable(&name)),
            |v| v,
        )?;
        channels.push(channel(name, data, physical_size, &unit));
    }
    Ok(channels)
}

/// Metres per `unit`. Igor writes SI symbols: "A" is the ampere, not the ångström.
fn metres(unit: &str) -> Option<f64> {
    if unit.trim() == "A" {
        None
    } else {
        metres_per(unit)
    }
}

/// Physical size [m] from two lengths in their units, when both are positive lengths.
fn physical_size_m((lx, x_unit): (f64, &str), (ly, y_unit): (f64, &str)) -> Option<(f64, f64)> {
    let (lx, ly) = (lx * metres(x_unit)?, ly * metres(y_unit)?);
    (lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()).then_some((lx, ly))
}

/// A channel with its values converted to metres when its unit is a length.
fn channel(name: String, mut data: ndarray::Array2<f64>, physical_size: Option<(f64, f64)>, unit: &str) -> Channel {
    let m = metres(unit);
    if let Some(m) = m {
        data.mapv_inplace(|v| v * m);
    }
    Channel {
        name,
        data,
        physical_size,
        unit: Some(unit.to_string()).filter(|u| !u.is_empty()),
        is_height: m.is_some(),
    }
}

/// The `Key: value` lines of an Asylum Research wave note.
fn parse_note(note: &str) -> Vec<(String, String)> {
    note.split(['\r', '\n'])
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect()
}

/// Asylum Research writes one data unit for all layers of an image; each channel's own unit
/// is in its note (`HeightUnit: m`) or follows from its name (`HeightRetrace`, `Phase1Trace`…).
fn asylum_unit(label: &str, note: &[(String, String)]) -> Option<String> {
    let mut base = label.strip_suffix("Retrace").or_else(|| label.strip_suffix("Trace")).unwrap_or(label);
    if let Some(i) = base.rfind("Mod").filter(|&i| base[i + 3..].bytes().all(|b| b.is_ascii_digit())) {
        base = &base[..i];
    }
    let key = format!("{base}Unit");
    if let Some((_, unit)) = note.iter().find(|(k, _)| *k == key) {
        return Some(unit.clone());
    }
    let quantity = base.strip_prefix("Nap").or_else(|| base.strip_prefix("DAC")).unwrap_or(base);
    const UNITS: &[(&str, &str)] = &[
        ("Height", "m"),
        ("ZSensor", "m"),
        ("Deflection", "m"),
        ("Amplitude", "m"),
        ("Phase", "deg"),
        ("Current", "A"),
        ("Frequency", "Hz"),
        ("Potential", "V"),
    ];
    UNITS.iter().find(|(prefix, _)| quantity.starts_with(prefix)).map(|(_, u)| u.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asylum_units_follow_names_and_note() {
        let note = parse_note("ScanSize: 5e-6\rAmplitudeUnit: V\r");
        assert_eq!(asylum_unit("HeightRetrace", &note).as_deref(), Some("m"));
        assert_eq!(asylum_unit("ZSensorTrace", &note).as_deref(), Some("m"));
        assert_eq!(asylum_unit("AmplitudeMod2Trace", &note).as_deref(), Some("V"));
        assert_eq!(asylum_unit("NapPhaseRetrace", &note).as_deref(), Some("deg"));
        assert_eq!(asylum_unit("UserIn0Trace", &note), None);
        assert_eq!(asylum_unit("CurrentTrace", &note).as_deref(), Some("A"));
        assert_eq!(metres("A"), None, "Igor's A is the ampere");
        assert_eq!(metres("nm"), Some(1e-9));
    }

    /// Bytes of a number in the wave's byte order.
    fn put(out: &mut [u8], at: usize, b: &[u8], endian: Endian) {
        let mut b = b.to_vec();
        if endian == Endian::Big {
            b.reverse();
        }
        out[at..at + b.len()].copy_from_slice(&b);
    }

    /// Set the checksum word at `at` so that the 16-bit words of `out[..len]` sum to zero.
    fn seal(out: &mut [u8], at: usize, len: usize, endian: Endian) {
        out[at..at + 2].fill(0);
        let word = |w: &[u8]| {
            if endian == Endian::Little {
                u16::from_le_bytes([w[0], w[1]])
            } else {
                u16::from_be_bytes([w[0], w[1]])
            }
        };
        let sum = out[..len].chunks_exact(2).fold(0u16, |s, w| s.wrapping_add(word(w)));
        let fix = 0u16.wrapping_sub(sum);
        out[at..at + 2].copy_from_slice(&if endian == Endian::Little { fix.to_le_bytes() } else { fix.to_be_bytes() });
    }

    /// A version 5 wave of f32 `layers`, each nx × ny (x fastest), in metres with pixel size
    /// `dx`, its layers labelled, and an Asylum-style note.
    fn wave5(endian: Endian, nx: usize, ny: usize, layers: &[Vec<f32>], labels: &[&str], note: &str) -> Vec<u8> {
        let npnts = nx * ny * layers.len();
        let wfm_size = 320 + 4 * npnts;
        let label_block = if labels.is_empty() { 0 } else { LABEL_BYTES * (layers.len() + 1) };
        let mut out = vec![0u8; 64 + wfm_size + note.len() + label_block];
        put(&mut out, 0, &5i16.to_le_bytes(), endian);
        put(&mut out, 4, &(wfm_size as i32).to_le_bytes(), endian);
        put(&mut out, 12, &(note.len() as i32).to_le_bytes(), endian);
        put(&mut out, 44, &(label_block as i32).to_le_bytes(), endian); // dimLabelsSize[2]
        let w = 64;
        put(&mut out, w + 12, &(npnts as i32).to_le_bytes(), endian);
        put(&mut out, w + 16, &2i16.to_le_bytes(), endian); // NT_FP32
        for (d, n) in [nx, ny, layers.len()].into_iter().enumerate() {
            put(&mut out, w + 68 + 4 * d, &(n as i32).to_le_bytes(), endian);
        }
        for d in 0..2 {
            put(&mut out, w + 84 + 8 * d, &2e-9f64.to_le_bytes(), endian); // sfA
            out[w + 152 + 4 * d] = b'm'; // dimUnits
        }
        out[w + 148] = b'm'; // dataUnits
        let mut at = 64 + 320;
        for v in layers.iter().flatten() {
            put(&mut out, at, &v.to_le_bytes(), endian);
            at += 4;
        }
        out[at..at + note.len()].copy_from_slice(note.as_bytes());
        at += note.len();
        for (k, l) in std::iter::once(&"").chain(labels).enumerate() {
            out[at + k * LABEL_BYTES..][..l.len()].copy_from_slice(l.as_bytes());
        }
        seal(&mut out, 2, 384, endian);
        out
    }

    #[test]
    fn version_5_in_both_byte_orders_with_labelled_layers() {
        // Layer 0 holds heights 0..6 [m], layer 1 a phase; three columns, two lines.
        let height: Vec<f32> = (0..6).map(|v| v as f32 * 1e-9).collect();
        let phase = vec![10.0f32; 6];
        for endian in [Endian::Little, Endian::Big] {
            let bytes = wave5(
                endian,
                3,
                2,
                &[height.clone(), phase.clone()],
                &["HeightTrace", "Phase1Retrace"],
                "ScanRate: 1\r",
            );
            assert!(Ibw.sniff(&bytes), "{endian:?}");
            let ch = Ibw.read(&bytes).unwrap();
            assert_eq!(ch.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), ["HeightTrace", "Phase1Retrace"]);
            let h = &ch[0];
            assert!(h.is_height && !ch[1].is_height);
            assert_eq!(ch[1].unit.as_deref(), Some("deg"));
            let (lx, ly) = h.physical_size.unwrap();
            assert!((lx - 6e-9).abs() < 1e-24 && (ly - 4e-9).abs() < 1e-24, "{lx} {ly}");
            // Igor's first line (0, 1, 2 nm) is the bottom of the image.
            let want = ndarray::array![[3e-9, 4e-9, 5e-9], [0.0, 1e-9, 2e-9]];
            assert!(h.data.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-15), "{endian:?}: {}", h.data);
            assert!(ch[1].data.iter().all(|&p| p == 10.0));
        }
    }

    #[test]
    fn unlabelled_layers_are_numbered_and_corrupt_headers_refused() {
        let layer = vec![1.0f32; 4];
        let bytes = wave5(Endian::Little, 2, 2, &[layer.clone(), layer], &[], "");
        let names: Vec<String> = Ibw.read(&bytes).unwrap().into_iter().map(|c| c.name).collect();
        assert_eq!(names, ["no name (1)", "no name (2)"]);
        let mut bad = bytes.clone();
        bad[100] ^= 1;
        assert!(Ibw.read(&bad).unwrap_err().contains("checksum"));
        // npnts no longer matching the dimensions, checksum restored: refused all the same.
        let mut bad = bytes;
        put(&mut bad, 64 + 12, &9i32.to_le_bytes(), Endian::Little);
        seal(&mut bad, 2, 384, Endian::Little);
        assert!(Ibw.read(&bad).unwrap_err().contains("do not match"));
    }

    #[test]
    fn version_2_profile() {
        // BinHeader2 (16 bytes) and WaveHeader2 (110 bytes), then 4 doubles, big-endian.
        let endian = Endian::Big;
        let mut out = vec![0u8; 126 + 32];
        put(&mut out, 0, &2i16.to_le_bytes(), endian);
        put(&mut out, 2, &(110 + 32i32).to_le_bytes(), endian); // wfmSize
        put(&mut out, 16, &4i16.to_le_bytes(), endian); // NT_FP64
        out[16 + 34] = b'm'; // dataUnits
        out[16 + 38..16 + 40].copy_from_slice(b"um"); // xUnits
        put(&mut out, 16 + 42, &4i32.to_le_bytes(), endian); // npnts
        put(&mut out, 16 + 48, &0.5f64.to_le_bytes(), endian); // hsA
        for (i, v) in [1e-9f64, 2e-9, 3e-9, 4e-9].iter().enumerate() {
            put(&mut out, 126 + 8 * i, &v.to_le_bytes(), endian);
        }
        seal(&mut out, 14, 126, endian);
        let ch = Ibw.read(&out).unwrap();
        assert_eq!(ch[0].data, ndarray::array![[1e-9, 2e-9, 3e-9, 4e-9]]);
        assert_eq!(ch[0].physical_size, Some((2e-6, 0.5e-6)));
        assert!(ch[0].is_height);
        out.truncate(140);
        assert!(Ibw.read(&out).unwrap_err().contains("truncated"));
    }
}
