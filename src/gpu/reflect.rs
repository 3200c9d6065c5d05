//! What a shader declares, read from its SPIR-V (niagara's `shaders.cpp`): the descriptor
//! bindings of set 0 and the specialization constants by name. Pipelines build their layouts
//! from this, and check what a call site binds or specializes against it, so the shader is the
//! one place a binding is declared.
//!
//! Only the few instructions that carry this are decoded (SPIR-V 1.6 §2.3, §3.32).

use crate::error::{Error, Result};

/// What a binding of set 0 holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    Uniform,
    Storage,
    /// A sampled image with the context's nearest clamp sampler (`sampler2D`).
    Sampled,
}

/// One binding a shader declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeclaredBinding {
    pub binding: u32,
    pub kind: Binding,
    /// The variable's (or its block's) name, for messages.
    pub name: String,
}

/// A specialization constant a shader declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeclaredConstant {
    pub id: u32,
    pub name: String,
}

/// Everything a pipeline needs to know about one shader's interface.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Reflection {
    pub bindings: Vec<DeclaredBinding>,
    pub constants: Vec<DeclaredConstant>,
}

const MAGIC: u32 = 0x0723_0203;
const OP_NAME: u32 = 5;
const OP_TYPE_IMAGE: u32 = 25;
const OP_TYPE_SAMPLED_IMAGE: u32 = 27;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_STRUCT: u32 = 30;
const OP_TYPE_POINTER: u32 = 32;
const OP_SPEC_CONSTANT_TRUE: u32 = 48;
const OP_SPEC_CONSTANT_FALSE: u32 = 49;
const OP_SPEC_CONSTANT: u32 = 50;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const DECORATION_SPEC_ID: u32 = 1;
const DECORATION_BLOCK: u32 = 2;
const DECORATION_BUFFER_BLOCK: u32 = 3;
const DECORATION_BINDING: u32 = 33;
const DECORATION_DESCRIPTOR_SET: u32 = 34;
const STORAGE_UNIFORM_CONSTANT: u32 = 0;
const STORAGE_UNIFORM: u32 = 2;
const STORAGE_STORAGE_BUFFER: u32 = 12;

/// A type the walk from a variable to its descriptor kind passes through.
#[derive(Clone, Copy)]
enum Type {
    Pointer { pointee: u32 },
    Array { element: u32 },
    Struct,
    Image,
    SampledImage,
}

/// Reads the interface of the shader `name` (for messages) from its SPIR-V words.
pub fn reflect(name: &str, words: &[u32]) -> Result<Reflection> {
    let bad = |what: String| Error::Invalid(format!("shader {name}: {what}"));
    if words.len() < 5 || words[0] != MAGIC {
        return Err(bad("not SPIR-V".into()));
    }
    let mut names = std::collections::HashMap::new();
    let mut types = std::collections::HashMap::new();
    let mut decorations: Vec<(u32, u32, u32)> = Vec::new();
    let mut variables: Vec<(u32, u32, u32)> = Vec::new();
    let mut spec_constants = Vec::new();
    let mut at = 5;
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xFFFF);
        if count == 0 || at + count > words.len() {
            return Err(bad(format!("truncated instruction at word {at}")));
        }
        let op = &words[at + 1..at + count];
        match opcode {
            OP_NAME if !op.is_empty() => {
                names.insert(op[0], literal_string(&op[1..]));
            }
            OP_DECORATE if op.len() >= 2 => decorations.push((op[0], op[1], op.get(2).copied().unwrap_or(0))),
            OP_TYPE_POINTER if op.len() >= 3 => {
                types.insert(op[0], Type::Pointer { pointee: op[2] });
            }
            OP_TYPE_ARRAY | OP_TYPE_RUNTIME_ARRAY if op.len() >= 2 => {
                types.insert(op[0], Type::Array { element: op[1] });
            }
            OP_TYPE_STRUCT if !op.is_empty() => {
                types.insert(op[0], Type::Struct);
            }
            OP_TYPE_IMAGE if !op.is_empty() => {
                types.insert(op[0], Type::Image);
            }
            OP_TYPE_SAMPLED_IMAGE if !op.is_empty() => {
                types.insert(op[0], Type::SampledImage);
            }
            OP_SPEC_CONSTANT_TRUE | OP_SPEC_CONSTANT_FALSE | OP_SPEC_CONSTANT if op.len() >= 2 => {
                spec_constants.push(op[1]);
            }
            OP_VARIABLE if op.len() >= 3 => variables.push((op[0], op[1], op[2])),
            _ => {}
        }
        at += count;
    }
    let decoration = |id: u32, which: u32| decorations.iter().find(|d| d.0 == id && d.1 == which).map(|d| d.2);

    let mut bindings = Vec::new();
    for &(ty, id, storage) in &variables {
        let Some(binding) = decoration(id, DECORATION_BINDING) else { continue };
        let name = names.get(&id).filter(|n| !n.is_empty()).cloned().unwrap_or_else(|| format!("%{id}"));
        let set = decoration(id, DECORATION_DESCRIPTOR_SET).unwrap_or(0);
        if set != 0 {
            return Err(bad(format!("`{name}` is in set {set}: pipelines push one set, set 0")));
        }
        // Follow the pointer, and any arrays, to what the variable holds.
        let mut held = match types.get(&ty) {
            Some(Type::Pointer { pointee }) => *pointee,
            _ => return Err(bad(format!("`{name}` is not a pointer variable"))),
        };
        while let Some(Type::Array { element }) = types.get(&held) {
            held = *element;
        }
        let kind = match (storage, types.get(&held)) {
            (STORAGE_UNIFORM_CONSTANT, Some(Type::SampledImage)) => Binding::Sampled,
            (STORAGE_UNIFORM, Some(Type::Struct)) if decoration(held, DECORATION_BUFFER_BLOCK).is_some() => {
                Binding::Storage
            }
            (STORAGE_UNIFORM, Some(Type::Struct)) if decoration(held, DECORATION_BLOCK).is_some() => Binding::Uniform,
            (STORAGE_STORAGE_BUFFER, Some(Type::Struct)) => Binding::Storage,
            (_, Some(Type::Image)) => return Err(bad(format!("`{name}`: separate images are not supported"))),
            _ => {
                return Err(bad(format!(
                    "`{name}`: binding {binding} holds a descriptor type this crate does not bind"
                )));
            }
        };
        // A block's variable is often unnamed; its type carries the name then.
        let name = if name.starts_with('%') { names.get(&held).cloned().unwrap_or(name) } else { name };
        bindings.push(DeclaredBinding { binding, kind, name });
    }
    bindings.sort_by_key(|b| b.binding);

    let constants = spec_constants
        .into_iter()
        .filter_map(|id| {
            let spec_id = decoration(id, DECORATION_SPEC_ID)?;
            Some(DeclaredConstant { id: spec_id, name: names.get(&id).cloned().unwrap_or_default() })
        })
        .collect();
    Ok(Reflection { bindings, constants })
}

/// A nul-terminated UTF-8 string packed four bytes a word, little end first.
fn literal_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).take_while(|&b| b != 0).collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::shaders;

    #[test]
    fn a_resolve_declares_its_uniforms_samplers_and_filter() {
        let r = reflect("resolve", shaders::SHADOW_MAP_RESOLVE_FRAG.words).unwrap();
        let kinds: Vec<_> = r.bindings.iter().map(|b| (b.binding, b.kind)).collect();
        use Binding::*;
        assert_eq!(kinds, [(0, Uniform), (1, Uniform), (2, Sampled), (3, Sampled), (4, Sampled)]);
        assert_eq!(r.bindings[4].name, "shadow_map");
        assert!(r.constants.iter().any(|c| c.id == 0 && c.name == "FILTER"), "{:?}", r.constants);
    }

    #[test]
    fn storage_buffers_are_told_from_uniform_buffers() {
        let r = reflect("silhouettes", shaders::SHADOW_VOLUME_SILHOUETTES_COMP.words).unwrap();
        let kinds: Vec<_> = r.bindings.iter().map(|b| b.kind).collect();
        assert_eq!(kinds[0], Binding::Uniform);
        assert!(kinds[1..].iter().all(|k| *k == Binding::Storage), "{kinds:?}");
    }

    #[test]
    fn garbage_is_an_error_naming_the_shader() {
        let e = reflect("broken.frag", &[1, 2, 3]).unwrap_err().to_string();
        assert!(e.contains("broken.frag"), "{e}");
        let mut words = shaders::COMPOSITE_COMPOSITE_FRAG.words.to_vec();
        words.truncate(7);
        words[5] = 0x00FF_0005; // an OpName longer than what follows
        assert!(reflect("cut.frag", &words).unwrap_err().to_string().contains("truncated"));
    }
}
