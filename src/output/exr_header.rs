//! One order for an OpenEXR header's attributes. The `exr` crate keeps custom attributes in a
//! hash map whose order changes from one process (and one map) to the next, so the same image
//! would be written with its header attributes shuffled: the pixels identical, the files not.
//! Sorting the attributes by name in the encoded bytes makes equal images equal files. The
//! header keeps its length, so the offset table that follows it stays valid.

/// Sorts the attributes of a single-part OpenEXR file's header, in place, by name. Files this
/// does not recognise (not OpenEXR, multi-part, a malformed header) are left as they are.
pub(super) fn sort_header_attributes(bytes: &mut [u8]) {
    const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
    const MULTI_PART: u8 = 0x10;
    if bytes.len() < 8 || bytes[..4] != MAGIC || bytes[5] & MULTI_PART != 0 {
        return;
    }
    let Some((spans, end)) = attributes(bytes, 8) else {
        return;
    };
    let mut sorted: Vec<(&[u8], &[u8])> = spans
        .iter()
        .map(|&(start, name_end, stop)| (&bytes[start..name_end], &bytes[start..stop]))
        .collect();
    sorted.sort_by(|a, b| a.0.cmp(b.0));
    let joined: Vec<u8> = sorted
        .iter()
        .flat_map(|(_, all)| all.iter().copied())
        .collect();
    bytes[8..end].copy_from_slice(&joined);
}

/// Byte offsets of one attribute: its start, the end of its name, its end.
type Span = (usize, usize, usize);

/// The attributes from `at` up to the header's terminating null byte, and the offset of the
/// terminator.
fn attributes(bytes: &[u8], mut at: usize) -> Option<(Vec<Span>, usize)> {
    let mut spans = Vec::new();
    let nul = |from: usize| -> Option<usize> {
        bytes
            .get(from..)?
            .iter()
            .position(|&b| b == 0)
            .map(|p| from + p)
    };
    loop {
        let name_end = nul(at)?;
        if name_end == at {
            return Some((spans, at));
        }
        let type_end = nul(name_end + 1)?;
        let size_at = type_end + 1;
        let size = i32::from_le_bytes(bytes.get(size_at..size_at + 4)?.try_into().ok()?);
        let stop = size_at
            .checked_add(4)?
            .checked_add(usize::try_from(size).ok()?)?;
        if stop > bytes.len() {
            return None;
        }
        spans.push((at, name_end, stop));
        at = stop;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attribute(name: &str, value: &[u8]) -> Vec<u8> {
        let mut v = name.as_bytes().to_vec();
        v.push(0);
        v.extend_from_slice(b"string\0");
        v.extend_from_slice(&(value.len() as i32).to_le_bytes());
        v.extend_from_slice(value);
        v
    }

    #[test]
    fn attributes_are_sorted_and_the_rest_is_kept() {
        let mut file = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        for (n, v) in [("zeta", &b"1"[..]), ("alpha", b"22"), ("mid", b"")] {
            file.extend(attribute(n, v));
        }
        file.push(0);
        file.extend_from_slice(b"offsets and pixels");
        let mut sorted = file.clone();
        sort_header_attributes(&mut sorted);
        let mut expected = file[..8].to_vec();
        for (n, v) in [("alpha", &b"22"[..]), ("mid", b""), ("zeta", b"1")] {
            expected.extend(attribute(n, v));
        }
        expected.push(0);
        expected.extend_from_slice(b"offsets and pixels");
        assert_eq!(sorted, expected);
        // A truncated header is left alone.
        let mut cut = file[..20].to_vec();
        sort_header_attributes(&mut cut);
        assert_eq!(cut, file[..20]);
    }
}
