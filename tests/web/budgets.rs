//! The page's file budgets in the browser: a zip bomb and a zip of 100 000 entries end in a clear
//! error within the budget and seconds, and of a dropped folder only the dataset's own files are
//! asked for (a 4 GB recording beside them is not).

use std::io::Cursor;

use artmesh::data::{self, FileSet, fixture};
use artmesh::fixtures::hostile;
use artmesh::web::app::WebDataset;
use js_sys::Uint8Array;
use wasm_bindgen::JsCast;
use wasm_bindgen_test::*;
use zip::write::SimpleFileOptions;

/// A zip holding `files` under `scan/` and `copies` entries `scan/gt/zeros{i}.bin` of `size`
/// zero bytes each.
fn zip_with_zeros(files: &FileSet, copies: usize, size: usize) -> Vec<u8> {
    hostile::inputs::zip_with_zeros(files, "scan", "gt/zeros", copies, size).unwrap()
}

fn seconds_since(t0: f64) -> f64 {
    (js_sys::Date::now() - t0) / 1000.0
}

#[wasm_bindgen_test]
fn a_zip_bomb_is_refused_in_the_browser() {
    // 120 entries of 10 MiB of zeros in gt/ (which is read whole): 1.3 GB from about 1.2 MB.
    let transforms: FileSet = [("transforms_train_start.json".into(), b"{}".to_vec())].into();
    let bytes = zip_with_zeros(&transforms, 120, 10 << 20);
    assert!(bytes.len() < 4 << 20, "{} bytes", bytes.len());
    let t0 = js_sys::Date::now();
    let e = data::read_zip("bomb.zip", &bytes).unwrap_err();
    let s = seconds_since(t0);
    let text = e.to_string();
    assert!(s < 5.0, "refused in {s:.1} s");
    assert!(
        text.starts_with("bomb.zip: the 121 files the dataset needs take 1258 MB"),
        "{text}"
    );
    assert!(text.contains("gt/zeros"), "{text}");
    assert!(text.contains("over the budget of 1074 MB"), "{text}");

    // One such entry whose headers say 100 bytes is cut off while it is decompressed.
    let mut lying = zip_with_zeros(&transforms, 1, 10 << 20);
    let name = b"scan/gt/zeros0.bin";
    let at: Vec<usize> = (0..lying.len() - name.len())
        .filter(|&i| &lying[i..i + name.len()] == name)
        .collect();
    assert_eq!(at.len(), 2);
    // The uncompressed size, 8 bytes before the name in the local header, 22 in the central.
    for size in [at[0] - 8, at[1] - 22] {
        lying[size..size + 4].copy_from_slice(&100u32.to_le_bytes());
    }
    let e = data::read_zip("lying.zip", &lying).unwrap_err();
    assert_eq!(
        (e.file.as_str(), e.field.as_deref()),
        ("lying.zip", Some("gt/zeros0.bin"))
    );
}

#[wasm_bindgen_test]
fn a_zip_of_100_000_entries_is_refused_in_the_browser() {
    let t0 = js_sys::Date::now();
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..100_000 {
        zip.start_file(format!("many/{i}.txt"), options).unwrap();
    }
    let bytes = zip.finish().unwrap().into_inner();
    let written = seconds_since(t0);
    let t0 = js_sys::Date::now();
    let e = data::read_zip("many.zip", &bytes).unwrap_err();
    let s = seconds_since(t0);
    assert!(s < 20.0, "refused in {s:.1} s (written in {written:.1} s)");
    assert_eq!(e.file, "many.zip");
    assert!(
        e.message
            .contains("more than the 50000 files a dataset may come with (100000 found)"),
        "{e}"
    );
}

/// The page's two questions for a dropped folder `scan/` holding `files` and the listed extras.
fn page_selection(files: &FileSet, extras: &[(&str, f64)]) -> Result<Vec<String>, String> {
    let mut paths: Vec<String> = files.keys().map(|p| format!("scan/{p}")).collect();
    let mut sizes: Vec<f64> = files.values().map(|b| b.len() as f64).collect();
    for (path, size) in extras {
        paths.push(path.to_string());
        sizes.push(*size);
    }
    let ask = |read: &[String]| {
        let contents = read
            .iter()
            .map(|p| Uint8Array::from(&files[p.strip_prefix("scan/").unwrap()][..]))
            .collect();
        WebDataset::files_needed(
            "scan".into(),
            paths.clone(),
            sizes.clone(),
            read.to_vec(),
            contents,
        )
        .map_err(|e| {
            let e = wasm_bindgen::JsValue::from(e).unchecked_into::<js_sys::Error>();
            String::from(e.message())
        })
    };
    let index = ask(&[])?;
    let frames = ask(&index)?;
    assert!(ask(&[index.clone(), frames.clone()].concat())?.is_empty());
    Ok([index, frames].concat())
}

#[wasm_bindgen_test]
fn a_dropped_folder_is_read_without_its_unrelated_big_file() {
    let files = fixture::small_dataset(fixture::FixtureParams::default())
        .to_files()
        .unwrap();
    let extras = [
        ("scan/capture.mp4", 4.0 * (1u64 << 30) as f64),
        ("scan/start/train/rgba/take2.mp4", 4.0 * (1u64 << 30) as f64),
        ("scan/.DS_Store", 10.0),
    ];
    let mut picked = page_selection(&files, &extras).unwrap();
    picked.sort();
    let want: Vec<String> = files.keys().map(|p| format!("scan/{p}")).collect();
    assert_eq!(picked, want);

    // Needed files past the budget, or a folder of too many files, are refused before reading.
    let too_big = page_selection(&files, &[("scan/gt/mesh.ply", 2.0 * (1u64 << 30) as f64)]);
    let e = too_big.unwrap_err();
    assert!(e.starts_with("scan: the "), "{e}");
    assert!(
        e.contains("(the largest: gt/mesh.ply, 2147 MB), over the budget"),
        "{e}"
    );
    let many: Vec<(String, f64)> = (0..50_001).map(|i| (format!("scan/x/{i}"), 1.0)).collect();
    let many: Vec<(&str, f64)> = many.iter().map(|(p, s)| (p.as_str(), *s)).collect();
    let e = page_selection(&files, &many).unwrap_err();
    assert!(e.contains("more than the 50000 files"), "{e}");
}
