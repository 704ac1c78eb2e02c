//! The `.abgs` binary grid (`abgs::io::abgs_bin`, `abgs_grid_serialize` /
//! `abgs_grid_deserialize`): a round trip gives the same grid bit for bit and
//! the same answer to every query; every corruption — each header byte
//! changed, every truncation, another version or byte order, counts that lie,
//! bad content behind a valid checksum, random changes — is an error, never a
//! panic, and never a grid that answers differently.

mod common;

use abgs::io::abgs_bin::{self, MAGIC, VERSION};
use abgs::sizing::SizeParams;
use abgs::{BuildOptions, Error, Grid};
use rand::{Rng, SeedableRng};

/// The checksum rewritten after an edit (as a forger would).
fn reseal(b: &mut [u8]) {
    let n = b.len() - 4;
    let crc = crc32fast::hash(&b[..n]);
    b[n..].copy_from_slice(&crc.to_le_bytes());
}

fn put_u32(b: &mut [u8], at: usize, x: u32) {
    b[at..at + 4].copy_from_slice(&x.to_le_bytes());
}

fn put_u64(b: &mut [u8], at: usize, x: u64) {
    b[at..at + 8].copy_from_slice(&x.to_le_bytes());
}

fn add_u64(b: &mut [u8], at: usize, d: i64) {
    let x = u64::from_le_bytes(b[at..at + 8].try_into().unwrap());
    put_u64(b, at, x.wrapping_add_signed(d));
}

/// A closed, sized grid of a few hundred triangles with an extra array.
fn small() -> Grid {
    let t = common::shapes::torus(12, 8);
    let s = t
        .vertices()
        .iter()
        .map(|p| 0.1 + 0.05 * (p[0] + 4.5))
        .collect();
    let mut g = Grid::from_arrays(
        t.vertices().to_vec(),
        t.triangles().to_vec(),
        Some(s),
        &BuildOptions::default(),
    )
    .unwrap();
    let h0 = g.vertices().iter().map(|p| p[2]).collect();
    g.set_point_array("h0", h0).unwrap();
    g
}

/// A shared model with computed sizes and an array.
fn sized_model(name: &str) -> Grid {
    let mut g = Grid::load(&common::shared_meshes().join(name)).unwrap();
    g.compute_sizes(&SizeParams::default()).unwrap();
    let a = g.vertices().iter().map(|p| p[0] - p[1]).collect();
    g.set_point_array("x_minus_y", a).unwrap();
    g
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

/// Same arrays bit for bit, same report, and the same answers (surface,
/// hinted, batch, volume) on near-surface, box and walking points.
fn assert_same(a: &Grid, b: &Grid, n_points: usize) {
    assert_eq!(
        bits(a.vertices().as_flattened()),
        bits(b.vertices().as_flattened())
    );
    assert_eq!(a.triangles(), b.triangles());
    assert_eq!(a.sizes().map(bits), b.sizes().map(bits));
    assert_eq!(a.point_arrays().len(), b.point_arrays().len());
    for (x, y) in a.point_arrays().iter().zip(b.point_arrays()) {
        assert_eq!(x.name, y.name);
        assert_eq!(bits(&x.values), bits(&y.values));
    }
    assert_eq!(a.report(), b.report());
    assert_eq!(a.bbox(), b.bbox());
    let diag = a.bbox().diagonal();
    let mut pts = abgs::sampling::near_surface_points(a, n_points, 0.02 * diag, 1);
    pts.extend(abgs::sampling::box_points(a, n_points, 0.2, 2));
    pts.extend(abgs::sampling::walk_points(a, n_points, 0.01 * diag, 3));
    let (mut ha, mut hb) = (u32::MAX, u32::MAX);
    for &p in &pts {
        let (x, y) = (a.closest(p, None).unwrap(), b.closest(p, None).unwrap());
        assert_eq!(x, y, "at {p:?}");
        assert_eq!(x.size.to_bits(), y.size.to_bits());
        let (x, y) = (
            a.query_size_hinted(p, &mut ha).unwrap(),
            b.query_size_hinted(p, &mut hb).unwrap(),
        );
        assert_eq!(x.to_bits(), y.to_bits());
        assert_eq!(ha, hb);
    }
    let vol: Vec<[f64; 3]> = pts.iter().step_by(7).copied().collect();
    for &p in &vol {
        assert_eq!(
            a.query_volume(p, 1.2).unwrap(),
            b.query_volume(p, 1.2).unwrap()
        );
    }
    let (mut oa, mut ob) = (vec![0.0; pts.len()], vec![0.0; pts.len()]);
    a.query_sizes(&pts, &mut oa).unwrap();
    b.query_sizes(&pts, &mut ob).unwrap();
    assert_eq!(bits(&oa), bits(&ob));
}

#[test]
fn round_trip_is_bit_identical_on_shared_models() {
    for name in ["gmsh_t20_component8.stl", "cgal_fandisk.off"] {
        let g = sized_model(name);
        let bytes = abgs_bin::encode(&g);
        assert_eq!(bytes.len(), abgs_bin::encoded_len(&g, true));
        assert_eq!(bytes[..8], MAGIC);
        let back = abgs_bin::decode(&bytes).unwrap();
        assert_same(&g, &back, 3000);
        assert_eq!(back.bvh().layout(), g.bvh().layout(), "{name}: BVH kept");
        // Encoding is deterministic and a fixed point.
        assert_eq!(abgs_bin::encode(&back), bytes, "{name}");
        // Without the layout: the BVH is rebuilt, the same one.
        let lean = abgs_bin::encode_with(&g, false);
        assert!(lean.len() < bytes.len());
        let rebuilt = abgs_bin::decode(&lean).unwrap();
        assert_same(&g, &rebuilt, 500);
        assert_eq!(rebuilt.bvh().layout(), g.bvh().layout());
        // Through a file, by extension.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("grid.abgs");
        g.save(&path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), bytes);
        assert_same(&g, &Grid::load(&path).unwrap(), 500);
        // Another kind of file under the name: refused after its first bytes.
        let stl = common::shared_meshes().join("gmsh_t20_component8.stl");
        std::fs::copy(stl, &path).unwrap();
        let e = Grid::load(&path).unwrap_err();
        assert!(e.to_string().contains("not an abgs grid"), "{e}");
        std::fs::write(&path, &bytes[..5]).unwrap();
        let e = Grid::load(&path).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
    }
}

#[test]
fn grids_without_sizes_or_arrays_round_trip() {
    let g = common::shapes::torus(9, 7);
    let b = abgs_bin::decode(&abgs_bin::encode(&g)).unwrap();
    assert!(b.sizes().is_none() && b.point_arrays().is_empty());
    assert_eq!(b.triangles(), g.triangles());
    for p in [
        [0.1, 0.2, 3.0],
        [2.0, 0.0, 0.0],
        [-4.0, 1.0, 0.2],
        [3.0, 0.0, 1.0],
    ] {
        // (The size is NaN without sizes: compare the printed hits.)
        let (x, y) = (b.closest(p, None).unwrap(), g.closest(p, None).unwrap());
        assert_eq!(format!("{x:?}"), format!("{y:?}"));
        assert!(x.size.is_nan());
    }
    let mut buf = vec![0u8; 10];
    assert!(abgs_bin::encode_into(&g, &mut buf).is_err());
    assert!(buf.iter().all(|&x| x == 0), "nothing written");
}

#[test]
fn every_changed_byte_and_every_truncation_is_refused() {
    let g = small();
    let bytes = abgs_bin::encode(&g);
    assert!(bytes.len() > 4000, "{}", bytes.len());
    // Each byte changed (two ways): the checksum, or a check before it, fails.
    for i in 0..bytes.len() {
        for x in [0x01u8, 0xFF] {
            let mut b = bytes.clone();
            b[i] ^= x;
            let e = abgs_bin::decode(&b).expect_err("a changed byte");
            assert!(
                matches!(e, Error::Parse { .. } | Error::UnsupportedFormat(_)),
                "byte {i}: {e}"
            );
        }
    }
    // Each truncation, and one byte too many.
    for n in 0..bytes.len() {
        let e = abgs_bin::decode(&bytes[..n]).expect_err("truncated");
        assert!(matches!(e, Error::Parse { .. }), "length {n}: {e}");
        if n >= abgs_bin::MIN_LEN {
            assert!(e.to_string().contains("truncated"), "{e}");
        }
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(abgs_bin::decode(&longer)
        .unwrap_err()
        .to_string()
        .contains("after the end"));
    assert!(abgs_bin::decode(
        b"solid ascii\nendsolid\n and more text, long enough for a header...."
    )
    .unwrap_err()
    .to_string()
    .contains("not an abgs grid"));
}

#[test]
fn version_byte_order_and_checksum_have_their_own_messages() {
    let bytes = abgs_bin::encode(&small());
    let mut b = bytes.clone();
    put_u32(&mut b, 8, VERSION + 1);
    reseal(&mut b);
    let e = abgs_bin::decode(&b).unwrap_err();
    assert!(matches!(e, Error::UnsupportedFormat(_)), "{e}");
    assert!(e.to_string().contains("version 2"), "{e}");
    // A big-endian writer's marker.
    let mut b = bytes.clone();
    b[12..16].copy_from_slice(&0x0A0B_0C0Du32.to_be_bytes());
    let e = abgs_bin::decode(&b).unwrap_err();
    assert!(matches!(e, Error::UnsupportedFormat(_)), "{e}");
    assert!(e.to_string().contains("big-endian"), "{e}");
    let mut b = bytes.clone();
    let last = b.len() - 10;
    b[last] ^= 4;
    assert!(abgs_bin::decode(&b)
        .unwrap_err()
        .to_string()
        .contains("checksum"));
}

/// Counts that lie, behind a valid checksum: refused before any allocation
/// (a count of 2^32 vertices would otherwise ask for 100 GB).
#[test]
fn lying_counts_are_refused() {
    let bytes = abgs_bin::encode(&small());
    let len = bytes.len() as u64;
    type Edit = Box<dyn Fn(&mut Vec<u8>)>;
    let cases: Vec<(&str, Edit)> = vec![
        (
            "vertices 2^32-1",
            Box::new(|b| put_u64(b, 24, u32::MAX as u64)),
        ),
        ("vertices 2^64-1", Box::new(|b| put_u64(b, 24, u64::MAX))),
        ("vertices + 1", Box::new(|b| add_u64(b, 24, 1))),
        ("vertices - 1", Box::new(|b| add_u64(b, 24, -1))),
        ("triangles 2^40", Box::new(|b| put_u64(b, 32, 1 << 40))),
        ("triangles - 1", Box::new(|b| add_u64(b, 32, -1))),
        ("triangles + 1", Box::new(|b| add_u64(b, 32, 1))),
        ("nodes + 1", Box::new(|b| add_u64(b, 40, 1))),
        ("nodes 2^63", Box::new(|b| put_u64(b, 40, 1 << 63))),
        ("nodes 0 with the flag", Box::new(|b| put_u64(b, 40, 0))),
        ("arrays 2^32-1", Box::new(|b| put_u32(b, 20, u32::MAX))),
        ("arrays 0", Box::new(|b| put_u32(b, 20, 0))),
        ("no sizes flag", Box::new(|b| put_u32(b, 16, 2))),
        ("unknown flag", Box::new(|b| put_u32(b, 16, 7))),
        ("reserved", Box::new(|b| put_u64(b, 56, 1))),
        ("history reserved", Box::new(|b| put_u64(b, 120, 1))),
        (
            "name length 2^32-1",
            Box::new(|b| {
                let at = name_length_offset(b);
                put_u32(b, at, u32::MAX)
            }),
        ),
        (
            "name length + 1",
            Box::new(|b| {
                let at = name_length_offset(b);
                put_u32(b, at, 3)
            }),
        ),
    ];
    for (what, f) in cases {
        let mut b = bytes.clone();
        f(&mut b);
        // Also the stated length made to agree with the lie.
        for fix_len in [false, true] {
            let mut c = b.clone();
            if fix_len {
                put_u64(&mut c, 48, len);
            }
            reseal(&mut c);
            let e = abgs_bin::decode(&c).expect_err(what);
            assert!(matches!(e, Error::Parse { .. }), "{what}: {e}");
        }
    }
}

/// Where the name length of the only array ("h0") sits: after the header,
/// history, vertices, triangles and sizes.
fn name_length_offset(b: &[u8]) -> usize {
    let rd = |at: usize| u64::from_le_bytes(b[at..at + 8].try_into().unwrap()) as usize;
    let (nv, nt) = (rd(24), rd(32));
    128 + 24 * nv + 12 * nt + 8 * nv
}

/// Bad content behind a valid checksum gets the error `from_arrays` gives.
#[test]
fn bad_content_is_refused_as_from_arrays_refuses_it() {
    let g = small();
    let bytes = abgs_bin::encode(&g);
    let (nv, nt) = (g.vertices().len(), g.triangles().len());
    let verts = 128;
    let tris = verts + 24 * nv;
    let sizes = tris + 12 * nt;
    let nodes = sizes + 8 * nv + (4 + 2 + 8 * nv);
    type Case = (&'static str, usize, Vec<u8>, fn(&Error) -> bool);
    let cases: Vec<Case> = vec![
        (
            "NaN coordinate",
            verts + 8,
            f64::NAN.to_le_bytes().to_vec(),
            |e| matches!(e, Error::NonFinite(_)),
        ),
        (
            "huge coordinate",
            verts,
            1e300f64.to_le_bytes().to_vec(),
            |e| matches!(e, Error::NonFinite(_)),
        ),
        (
            "index out of range",
            tris + 4,
            (nv as u32).to_le_bytes().to_vec(),
            |e| matches!(e, Error::OutOfRange(_)),
        ),
        ("repeated corner", tris, 0u32.to_le_bytes().repeat(2), |e| {
            matches!(e, Error::InvalidArgument(_))
        }),
        ("zero size", sizes, 0f64.to_le_bytes().to_vec(), |e| {
            matches!(e, Error::InvalidSize(_))
        }),
        (
            "negative size",
            sizes + 8,
            (-1f64).to_le_bytes().to_vec(),
            |e| matches!(e, Error::InvalidSize(_)),
        ),
        ("history", 64, 1u64.to_le_bytes().to_vec(), |e| {
            matches!(e, Error::InvalidArgument(_))
        }),
        ("BVH root", nodes, [0u8; 8].to_vec(), |e| {
            matches!(e, Error::InvalidArgument(_))
        }),
        (
            "BVH slot",
            bytes.len() - 8,
            u32::MAX.to_le_bytes().to_vec(),
            |e| matches!(e, Error::InvalidArgument(_)),
        ),
    ];
    for (what, at, new, ok) in cases {
        let mut b = bytes.clone();
        b[at..at + new.len()].copy_from_slice(&new);
        reseal(&mut b);
        let e = abgs_bin::decode(&b).expect_err(what);
        assert!(ok(&e), "{what}: {e}");
    }
}

/// Random edits behind a valid checksum (what the fuzz target does, briefly):
/// an error, or a grid that answers as a grid built from the same arrays.
#[test]
fn random_edits_give_an_error_or_a_correct_grid() {
    let bytes = abgs_bin::encode(&small());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (mut ok, mut refused) = (0, 0);
    for _ in 0..3000 {
        let mut b = bytes.clone();
        for _ in 0..rng.gen_range(1..4) {
            let i = rng.gen_range(0..b.len() - 4);
            b[i] = rng.gen();
        }
        reseal(&mut b);
        match abgs_bin::decode(&b) {
            Err(e) => {
                assert!(!e.to_string().is_empty());
                refused += 1;
            }
            Ok(g) => {
                ok += 1;
                let fresh = Grid::from_parts(g.to_parts(false)).unwrap();
                for p in [[0.3, 0.1, 0.2], [3.5, -0.2, 0.4], [0.0, 0.0, 3.0]] {
                    assert_eq!(g.closest(p, None).unwrap(), fresh.closest(p, None).unwrap());
                    // To rounding only: the two trees scan different triangles,
                    // each minimum exact to rounding (see fuzz/src/serialized.rs).
                    let a = g.query_volume(p, 1.3).unwrap().size;
                    let b = fresh.query_volume(p, 1.3).unwrap().size;
                    let tol = 1e-9 * a.max(b) + 1.3f64.ln() * 1e-6 * (g.bvh().coord_scale + 4.0);
                    assert!((a - b).abs() <= tol, "{a} {b} at {p:?}");
                }
            }
        }
    }
    assert!(ok > 100 && refused > 100, "{ok} loaded, {refused} refused");
}
