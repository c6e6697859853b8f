//! The Gmsh file the `gmsh_binary` target reads from fuzzer bytes; shared
//! (by `#[path]`) with the test that replays its seeds and crashes.

/// A binary Gmsh 4.1 `$MeshFormat` header in the byte order the first
/// byte of `data` picks (even: little-endian, odd: big-endian), then the
/// rest of `data`; `None` for empty data.
pub(crate) fn gmsh_binary_file(data: &[u8]) -> Option<Vec<u8>> {
    let (&order, body) = data.split_first()?;
    let one = if order % 2 == 0 {
        1i32.to_le_bytes()
    } else {
        1i32.to_be_bytes()
    };
    let mut file = b"$MeshFormat\n4.1 1 8\n".to_vec();
    file.extend(one);
    file.extend(b"\n$EndMeshFormat\n");
    file.extend(body);
    Some(file)
}
