//! PNG encoding: signature, IHDR, one IDAT with a zlib stream from
//! `miniz_oxide`, IEND, each chunk with the CRC-32 computed here. Every row
//! uses filter type 2 (up: the difference from the row above), which turns
//! a plot's background, bands and vertical grid lines into runs of zeros,
//! and deflate runs at its fastest level: a 1600 x 1400 Bode plot
//! compresses in 8 ms to 190 kB, where no filter at level 6 took 50 ms for
//! 152 kB (the report is written after the diagnosis, on one core).

/// Encodes `rgb` (`width * height * 3` bytes, rows top down) as an 8-bit
/// RGB, non-interlaced PNG.
pub(crate) fn encode(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    let stride = width as usize * 3;
    let mut raw = Vec::with_capacity((stride + 1) * height as usize);
    let mut above: &[u8] = &[];
    for row in rgb.chunks_exact(stride) {
        raw.push(2);
        if above.is_empty() {
            raw.extend_from_slice(row);
        } else {
            raw.extend(row.iter().zip(above).map(|(b, a)| b.wrapping_sub(*a)));
        }
        above = row;
    }
    let mut ihdr = Vec::with_capacity(13);
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    // Bit depth 8, colour type 2 (RGB), deflate, adaptive filtering, no interlace.
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);

    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(
        &mut out,
        b"IDAT",
        &miniz_oxide::deflate::compress_to_vec_zlib(&raw, 1),
    );
    chunk(&mut out, b"IEND", &[]);
    out
}

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// CRC-32 (ISO-HDLC, reflected polynomial 0xEDB88320), as PNG specifies.
pub(crate) fn crc32(bytes: &[u8]) -> u32 {
    !bytes.iter().fold(!0u32, |crc, &b| {
        CRC_TABLE[((crc ^ u32::from(b)) & 0xff) as usize] ^ (crc >> 8)
    })
}

const CRC_TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut n = 0;
    while n < 256 {
        let mut c = n as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 == 1 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        table[n] = c;
        n += 1;
    }
    table
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc_check_values() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
        // The CRC of an IEND chunk is a well-known constant.
        assert_eq!(crc32(b"IEND"), 0xAE42_6082);
    }

    #[test]
    fn layout_of_a_tiny_image() {
        let png = encode(1, 1, &[255, 0, 0]);
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&png[8..16], b"\0\0\0\x0dIHDR");
        assert_eq!(&png[png.len() - 12..], b"\0\0\0\0IEND\xae\x42\x60\x82");
    }
}
