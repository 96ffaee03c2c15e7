//! Raw FFI to the vendored METIS 5 (bindings generated upstream, unchanged).
#![allow(non_upper_case_globals)]
#![allow(non_camel_case_types)]
#![allow(non_snake_case)]

include!("../gen/bindings.rs");
