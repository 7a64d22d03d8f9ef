//! glTF files the integration tests write: one binary buffer with its views and accessors,
//! as a `.gltf` (the buffer as a data URI) or a `.glb` (the buffer as its BIN chunk).

use serde_json::{json, Value};

/// glTF accessor component types (`componentType`, the GL enums).
pub const UNSIGNED_BYTE: u32 = 5121;
pub const UNSIGNED_SHORT: u32 = 5123;
pub const UNSIGNED_INT: u32 = 5125;
pub const FLOAT: u32 = 5126;

pub fn base64(bytes: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Accumulates one binary buffer with its views and accessors, then writes a `.gltf` (the
/// buffer as a data URI) or a `.glb` (the buffer as its BIN chunk).
#[derive(Default)]
pub struct Builder {
    pub bin: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
}

impl Builder {
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    pub fn accessor(&mut self, bytes: &[u8], component: u32, ty: &str, count: usize) -> usize {
        let view = self.view(bytes);
        self.accessors.push(
            json!({"bufferView": view, "componentType": component, "type": ty, "count": count}),
        );
        self.accessors.len() - 1
    }

    pub fn floats(&mut self, values: &[f32], ty: &str) -> usize {
        let per = match ty {
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            _ => 1,
        };
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.accessor(&bytes, FLOAT, ty, values.len() / per)
    }

    pub fn u16s(&mut self, values: &[u16]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.accessor(&bytes, UNSIGNED_SHORT, "SCALAR", values.len())
    }

    pub fn document(&self, mut rest: Value, buffer_uri: Option<String>) -> Value {
        let mut buffer = json!({"byteLength": self.bin.len()});
        if let Some(uri) = buffer_uri {
            buffer["uri"] = json!(uri);
        }
        rest["asset"] = json!({"version": "2.0"});
        if !self.bin.is_empty() {
            rest["buffers"] = json!([buffer]);
            rest["bufferViews"] = json!(self.views);
            rest["accessors"] = json!(self.accessors);
        }
        rest
    }

    pub fn gltf(&self, rest: Value) -> String {
        let uri = format!("data:application/octet-stream;base64,{}", base64(&self.bin));
        self.document(rest, Some(uri)).to_string()
    }

    pub fn glb(&self, rest: Value) -> Vec<u8> {
        glb(
            self.document(rest, None).to_string().as_bytes(),
            Some(&self.bin),
        )
    }
}

pub fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let padded = |v: &[u8], with: u8| {
        let mut v = v.to_vec();
        while !v.len().is_multiple_of(4) {
            v.push(with);
        }
        v
    };
    let mut body = Vec::new();
    let json = padded(json, b' ');
    body.extend((json.len() as u32).to_le_bytes());
    body.extend(b"JSON");
    body.extend(&json);
    if let Some(bin) = bin {
        let bin = padded(bin, 0);
        body.extend((bin.len() as u32).to_le_bytes());
        body.extend(b"BIN\0");
        body.extend(&bin);
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((body.len() + 12) as u32).to_le_bytes());
    out.extend(body);
    out
}
