//! A stored (uncompressed) zip archive writer (PKWARE APPNOTE 6.3, §4.3): local headers, the data,
//! the central directory and its end record; no compression, no ZIP64 (every file and the archive
//! stay below 4 GiB and 65 535 entries, which a job's outputs do: at most 100 operations).
//! G-code compresses well, but a stored archive opens everywhere and needs no codec.

/// Fixed DOS date of every entry: 1980-01-01 00:00 (the archive of a job is the same bytes
/// whenever it is made).
const DOS_DATE: u16 = (1 << 5) | 1;

/// The archive of `files` (name, contents), in order.
///
/// # Errors
/// When a file or the archive is too large for a zip without ZIP64.
pub fn stored(files: &[(String, Vec<u8>)]) -> Result<Vec<u8>, String> {
    let too_large = || "the outputs are too large for one zip archive (4 GiB)".to_owned();
    let mut out = Vec::new();
    let mut central = Vec::new();
    for (name, data) in files {
        let offset = u32::try_from(out.len()).map_err(|_| too_large())?;
        let size = u32::try_from(data.len()).map_err(|_| too_large())?;
        let name_len = u16::try_from(name.len()).map_err(|_| too_large())?;
        let crc = crc32fast::hash(data);
        // Local file header.
        out.extend_from_slice(&0x0403_4b50_u32.to_le_bytes());
        common(&mut out, crc, size, name_len);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(data);
        // Central directory header.
        central.extend_from_slice(&0x0201_4b50_u32.to_le_bytes());
        central.extend_from_slice(&20_u16.to_le_bytes()); // made by: MS-DOS, version 2.0
        common(&mut central, crc, size, name_len);
        central.extend_from_slice(&0_u16.to_le_bytes()); // comment length
        central.extend_from_slice(&0_u16.to_le_bytes()); // disk number
        central.extend_from_slice(&0_u16.to_le_bytes()); // internal attributes
        central.extend_from_slice(&0_u32.to_le_bytes()); // external attributes
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
    }
    let count = u16::try_from(files.len()).map_err(|_| too_large())?;
    let central_offset = u32::try_from(out.len()).map_err(|_| too_large())?;
    let central_size = u32::try_from(central.len()).map_err(|_| too_large())?;
    out.extend_from_slice(&central);
    // End of central directory record.
    out.extend_from_slice(&0x0605_4b50_u32.to_le_bytes());
    out.extend_from_slice(&0_u16.to_le_bytes()); // this disk
    out.extend_from_slice(&0_u16.to_le_bytes()); // disk with the directory
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&central_size.to_le_bytes());
    out.extend_from_slice(&central_offset.to_le_bytes());
    out.extend_from_slice(&0_u16.to_le_bytes()); // comment length
    u32::try_from(out.len()).map_err(|_| too_large())?;
    Ok(out)
}

/// The fields local and central headers share, from "version needed" to "extra field length".
fn common(out: &mut Vec<u8>, crc: u32, size: u32, name_len: u16) {
    out.extend_from_slice(&10_u16.to_le_bytes()); // version needed: 1.0 (stored)
    out.extend_from_slice(&0x0800_u16.to_le_bytes()); // flags: names are UTF-8
    out.extend_from_slice(&0_u16.to_le_bytes()); // method: stored
    out.extend_from_slice(&0_u16.to_le_bytes()); // time 00:00
    out.extend_from_slice(&DOS_DATE.to_le_bytes());
    out.extend_from_slice(&crc.to_le_bytes());
    out.extend_from_slice(&size.to_le_bytes()); // compressed size
    out.extend_from_slice(&size.to_le_bytes()); // uncompressed size
    out.extend_from_slice(&name_len.to_le_bytes());
    out.extend_from_slice(&0_u16.to_le_bytes()); // extra field length
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_archive_lists_its_files_with_their_checksums() {
        let files = vec![("a.txt".to_owned(), b"hello".to_vec()), ("b/c.nc".to_owned(), Vec::new())];
        let zip = stored(&files).unwrap();
        assert_eq!(&zip[..4], b"PK\x03\x04");
        // Local header of a.txt: 30 bytes, the name, the data.
        assert_eq!(&zip[14..18], &crc32fast::hash(b"hello").to_le_bytes());
        assert_eq!(&zip[30..35], b"a.txt");
        assert_eq!(&zip[35..40], b"hello");
        let end = &zip[zip.len() - 22..];
        assert_eq!(&end[..4], b"PK\x05\x06");
        assert_eq!(u16::from_le_bytes([end[10], end[11]]), 2);
        let directory = u32::from_le_bytes([end[16], end[17], end[18], end[19]]) as usize;
        assert_eq!(&zip[directory..directory + 4], b"PK\x01\x02");
    }
}
