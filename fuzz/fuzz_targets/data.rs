//! The data reader: a document made from the input's first bytes (accessors of any component
//! type, type, count, offset and normalization, some sparse; buffer views of any offset,
//! length and stride; meshes, an animation and a skin that use them) over a buffer of the
//! bytes that follow — a .glb's BIN chunk, or (as the first byte says) a .bin file beside a
//! .gltf, read a part at a time — validated with every data check: the accessors' elements
//! decoded from wherever the views put them, in bounds or not.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use std::sync::OnceLock;
use velvet::asset::glb;

/// Reads numbers off the front of the input; zeros once it runs out.
struct Cursor<'a>(&'a [u8]);

impl Cursor<'_> {
    fn byte(&mut self) -> u8 {
        match self.0.split_first() {
            Some((b, rest)) => {
                self.0 = rest;
                *b
            }
            None => 0,
        }
    }

    fn small(&mut self, below: u32) -> u32 {
        u32::from(self.byte()) % below.max(1)
    }

    fn number(&mut self) -> u32 {
        u32::from_le_bytes([self.byte(), self.byte(), 0, 0])
    }
}

const COMPONENT_TYPES: [u32; 7] = [5120, 5121, 5122, 5123, 5125, 5126, 5124];
const TYPES: [&str; 7] = ["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"];

/// A folder of this process's own for the .gltf inputs' buffer files.
fn folder() -> &'static Path {
    static FOLDER: OnceLock<std::path::PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("velvet-fuzz-data-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a folder for the buffer files");
        dir
    })
}

fuzz_target!(|input: &[u8]| {
    let mut at = Cursor(input);
    let as_file = at.small(2) == 1;
    let bin_len = at.number() as usize % 4096;
    let views: Vec<String> = (0..1 + at.small(4))
        .map(|_| {
            let stride = match at.small(3) {
                0 => String::new(),
                _ => format!(r#","byteStride":{}"#, at.small(64)),
            };
            format!(
                r#"{{"buffer":0,"byteOffset":{},"byteLength":{}{stride}}}"#,
                at.number() % 4096,
                at.number() % 4096
            )
        })
        .collect();
    let view_count = views.len() as u32;
    let accessors: Vec<String> = (0..1 + at.small(6))
        .map(|_| {
            let mut fields = vec![
                format!(r#""componentType":{}"#, COMPONENT_TYPES[at.small(7) as usize]),
                format!(r#""type":"{}""#, TYPES[at.small(7) as usize]),
                format!(r#""count":{}"#, at.number() % 512),
            ];
            if at.small(4) > 0 {
                fields.push(format!(r#""bufferView":{}"#, at.small(view_count + 1)));
                fields.push(format!(r#""byteOffset":{}"#, at.small(64)));
            }
            if at.small(4) == 0 {
                fields.push(r#""normalized":true"#.to_string());
            }
            if at.small(3) == 0 {
                fields.push(r#""min":[0,0,0],"max":[1,1,1]"#.to_string());
            }
            if at.small(4) == 0 {
                fields.push(format!(
                    r#""sparse":{{"count":{},"indices":{{"bufferView":{},"byteOffset":{},"componentType":{}}},"values":{{"bufferView":{},"byteOffset":{}}}}}"#,
                    1 + at.small(16),
                    at.small(view_count),
                    at.small(32),
                    [5121, 5123, 5125][at.small(3) as usize],
                    at.small(view_count),
                    at.small(32)
                ));
            }
            format!("{{{}}}", fields.join(","))
        })
        .collect();
    let n = accessors.len() as u32;
    let mut pick = || at.small(n);
    let uri = if as_file { r#","uri":"fuzz.bin""# } else { "" };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{bin_len}{uri}}}],
        "bufferViews":[{}],"accessors":[{}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":{},"NORMAL":{},"TANGENT":{},"TEXCOORD_0":{},"JOINTS_0":{},"WEIGHTS_0":{}}},"indices":{},"mode":{}}}]}}],
        "nodes":[{{"mesh":0,"skin":0}},{{}}],
        "skins":[{{"joints":[1],"inverseBindMatrices":{}}}],
        "animations":[{{"channels":[{{"sampler":0,"target":{{"node":1,"path":"rotation"}}}}],
            "samplers":[{{"input":{},"output":{},"interpolation":"LINEAR"}}]}}]}}"#,
        views.join(","),
        accessors.join(","),
        pick(),
        pick(),
        pick(),
        pick(),
        pick(),
        pick(),
        pick(),
        pick() % 7,
        pick(),
        pick(),
        pick()
    );
    let rest = at.0;
    let bin: Vec<u8> = rest.iter().copied().cycle().take(bin_len).collect();
    let (path, loaded) = if as_file {
        let path = folder().join("fuzz.gltf");
        std::fs::write(folder().join("fuzz.bin"), &bin).expect("the buffer file is written");
        let loaded = velvet::asset::load_bytes_with(&path, json.as_bytes(), &velvet_fuzz::options());
        (path, loaded)
    } else {
        let path = Path::new("/nonexistent/fuzz.glb").to_path_buf();
        let file = glb::join(json.as_bytes(), Some(&bin));
        let loaded = velvet::asset::load_bytes_with(&path, &file, &velvet_fuzz::options());
        (path, loaded)
    };
    let _ = velvet_fuzz::validator().validate_loaded(&path, loaded);
});
