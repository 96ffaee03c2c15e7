//! NumPy `.npz` archives in memory: named arrays of `f64`, `i64`, `bool` and unicode strings
//! built into bytes (what `np.savez` writes: a zip of `.npy` files, stored uncompressed), and
//! read back with every shape and type checked, so a torn or edited archive is a message naming
//! the array, never a panic.
//!
//! `npyz` encodes and decodes each `.npy` (header, dtype, shape, UTF-32 strings); `zip` holds
//! them.

use npyz::WriterBuilder;
use std::io::{Cursor, Read, Write};

/// An archive being built: add arrays, then [`NpzOut::finish`].
pub(crate) struct NpzOut {
    zip: zip::ZipWriter<Cursor<Vec<u8>>>,
    /// One `.npy` at a time, reused.
    buffer: Vec<u8>,
}

fn io_error(e: impl std::fmt::Display) -> std::io::Error {
    std::io::Error::other(e.to_string())
}

impl NpzOut {
    /// An empty archive.
    pub(crate) fn new() -> Self {
        NpzOut {
            zip: zip::ZipWriter::new(Cursor::new(Vec::new())),
            buffer: Vec::new(),
        }
    }

    /// Add `name.npy` holding the `.npy` bytes in `self.buffer`.
    fn store(&mut self, name: &str) -> std::io::Result<()> {
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .large_file(self.buffer.len() as u64 >= u32::MAX as u64);
        self.zip
            .start_file(format!("{name}.npy"), options)
            .map_err(io_error)?;
        self.zip.write_all(&self.buffer)
    }

    /// Encode `values` with dtype `dtype` and `shape` into the buffer, then store it as `name`.
    fn add<T: npyz::Serialize + ?Sized, I: IntoIterator>(
        &mut self,
        name: &str,
        dtype: npyz::DType,
        shape: &[usize],
        values: I,
    ) -> std::io::Result<()>
    where
        I::Item: std::borrow::Borrow<T>,
    {
        self.buffer.clear();
        let shape: Vec<u64> = shape.iter().map(|&s| s as u64).collect();
        let mut w = npyz::WriteOptions::<T>::new()
            .dtype(dtype)
            .shape(&shape)
            .writer(&mut self.buffer)
            .begin_nd()?;
        for v in values {
            w.push(std::borrow::Borrow::borrow(&v))?;
        }
        w.finish()?;
        self.store(name)
    }

    /// Add a `float64` array of `shape` (C order; `[]`: a scalar).
    pub(crate) fn f64s<'a>(
        &mut self,
        name: &str,
        shape: &[usize],
        values: impl IntoIterator<Item = &'a f64>,
    ) -> std::io::Result<()> {
        self.add::<f64, _>(name, plain("<f8"), shape, values)
    }

    /// Add an `int64` array of `shape` (C order; `[]`: a scalar).
    pub(crate) fn i64s(
        &mut self,
        name: &str,
        shape: &[usize],
        values: impl IntoIterator<Item = usize>,
    ) -> std::io::Result<()> {
        let values = values.into_iter().map(|v| v as i64);
        self.add::<i64, _>(name, plain("<i8"), shape, values)
    }

    /// Add a `bool` array of `shape`.
    pub(crate) fn bools(
        &mut self,
        name: &str,
        shape: &[usize],
        values: impl IntoIterator<Item = bool>,
    ) -> std::io::Result<()> {
        self.add::<bool, _>(name, plain("|b1"), shape, values)
    }

    /// Add a unicode string array (`<UN`, N the longest string's characters, at least 1) of
    /// `shape`.
    pub(crate) fn strs(
        &mut self,
        name: &str,
        shape: &[usize],
        values: &[&str],
    ) -> std::io::Result<()> {
        let width = values
            .iter()
            .map(|s| s.chars().count())
            .max()
            .unwrap_or(0)
            .max(1);
        self.add::<str, _>(
            name,
            plain(&format!("<U{width}")),
            shape,
            values.iter().copied(),
        )
    }

    /// The archive's bytes.
    pub(crate) fn finish(self) -> std::io::Result<Vec<u8>> {
        Ok(self.zip.finish().map_err(io_error)?.into_inner())
    }
}

/// The dtype `descr` (one of the constant ones above, always valid).
fn plain(descr: &str) -> npyz::DType {
    npyz::DType::Plain(
        descr
            .parse()
            .unwrap_or_else(|_| unreachable!("{descr} is a dtype")),
    )
}

/// An archive being read. Every getter's error names the array and says what is wrong.
pub(crate) struct NpzIn<'a> {
    zip: zip::ZipArchive<Cursor<&'a [u8]>>,
}

/// One array as read: its shape and its values in C order.
pub(crate) struct Array<T> {
    /// Shape (`[]` for a scalar).
    pub(crate) shape: Vec<usize>,
    /// Values, C order.
    pub(crate) values: Vec<T>,
}

impl<'a> NpzIn<'a> {
    /// Open the archive in `bytes`.
    pub(crate) fn new(bytes: &'a [u8]) -> Result<Self, String> {
        zip::ZipArchive::new(Cursor::new(bytes))
            .map(|zip| NpzIn { zip })
            .map_err(|e| format!("not a NumPy .npz archive ({e})"))
    }

    /// Array `name` of element type `T` (what the dtype must decode to).
    fn read<T: npyz::Deserialize>(&mut self, name: &str) -> Result<Array<T>, String> {
        let bad = |what: String| format!("array '{name}': {what}");
        let mut file = self
            .zip
            .by_name(&format!("{name}.npy"))
            .map_err(|e| bad(format!("missing ({e})")))?;
        let size = file.size();
        let mut bytes = Vec::with_capacity(size.min(1 << 32) as usize);
        file.read_to_end(&mut bytes)
            .map_err(|e| bad(format!("cannot be read ({e})")))?;
        let npy = npyz::NpyFile::new(&bytes[..]).map_err(|e| bad(format!("not a .npy ({e})")))?;
        if npy.order() != npyz::Order::C {
            return Err(bad(
                "is in Fortran order; linkage writes C order".to_string()
            ));
        }
        let shape: Vec<usize> = npy.shape().iter().map(|&s| s as usize).collect();
        // A torn header must not make us allocate what the file does not hold.
        let count = shape.iter().try_fold(1usize, |a, &s| a.checked_mul(s));
        let element = npy.dtype().num_bytes().unwrap_or(1).max(1);
        match count {
            Some(n) if n.checked_mul(element).is_some_and(|b| b <= bytes.len()) => {}
            _ => {
                return Err(bad(format!(
                    "shape {shape:?} is larger than the {} bytes stored",
                    bytes.len()
                )))
            }
        }
        let dtype = npy.dtype().descr();
        let values = npy.into_vec::<T>().map_err(|e| {
            bad(format!(
                "cannot be read as {} ({dtype}: {e})",
                std::any::type_name::<T>()
            ))
        })?;
        Ok(Array { shape, values })
    }

    /// Whether the archive holds array `name`.
    pub(crate) fn has(&mut self, name: &str) -> bool {
        self.zip.by_name(&format!("{name}.npy")).is_ok()
    }

    /// A `float64` array.
    pub(crate) fn f64s(&mut self, name: &str) -> Result<Array<f64>, String> {
        self.read(name)
    }

    /// An integer array (any integer dtype that fits), as non-negative `usize`.
    pub(crate) fn usizes(&mut self, name: &str) -> Result<Array<usize>, String> {
        let a = self.read::<i64>(name)?;
        let values = a
            .values
            .iter()
            .map(|&v| usize::try_from(v))
            .collect::<Result<Vec<usize>, _>>()
            .map_err(|_| format!("array '{name}': holds a negative number"))?;
        Ok(Array {
            shape: a.shape,
            values,
        })
    }

    /// A `bool` array.
    pub(crate) fn bools(&mut self, name: &str) -> Result<Array<bool>, String> {
        self.read(name)
    }

    /// A unicode string array.
    pub(crate) fn strings(&mut self, name: &str) -> Result<Array<String>, String> {
        self.read(name)
    }
}

impl<T> Array<T> {
    /// The values of a `[n]` array; `n` must be `len` when given.
    pub(crate) fn list(self, name: &str, len: Option<usize>) -> Result<Vec<T>, String> {
        match (self.shape.as_slice(), len) {
            ([n], Some(l)) if *n != l => Err(format!("array '{name}' has {n} values, not {l}")),
            ([_], _) => Ok(self.values),
            (s, _) => Err(format!("array '{name}' has shape {s:?}, not one dimension")),
        }
    }

    /// The one value of a scalar (shape `[]`).
    pub(crate) fn scalar(mut self, name: &str) -> Result<T, String> {
        match (self.shape.as_slice(), self.values.pop()) {
            ([], Some(v)) => Ok(v),
            (s, _) => Err(format!("array '{name}' has shape {s:?}, not a scalar")),
        }
    }
}

impl<T: Clone> Array<T> {
    /// The rows of a `[rows, cols]` array; `rows` must be `len` when given.
    pub(crate) fn rows(
        self,
        name: &str,
        len: Option<usize>,
        cols: usize,
    ) -> Result<Vec<Vec<T>>, String> {
        match self.shape.as_slice() {
            [r, c] if *c == cols && len.is_none_or(|l| l == *r) => Ok(self
                .values
                .chunks(cols.max(1))
                .take(*r)
                .map(<[T]>::to_vec)
                .collect()),
            s => Err(format!(
                "array '{name}' has shape {s:?}, not [{}, {cols}]",
                len.map(|l| l.to_string())
                    .unwrap_or_else(|| "n".to_string())
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_come_back_with_their_shapes_and_bits() {
        let floats = [
            0.12499999999999999,
            -0.0,
            f64::MIN_POSITIVE / 3.0,
            1e308,
            5.0,
            6.0,
        ];
        let mut out = NpzOut::new();
        out.f64s("a", &[3, 2], &floats).unwrap();
        out.i64s("n", &[2], [1, 7]).unwrap();
        out.f64s("s", &[], &[0.5]).unwrap();
        out.strs("names", &[2], &["α/β", ""]).unwrap();
        out.bools("b", &[1, 2], [true, false]).unwrap();
        let bytes = out.finish().unwrap();
        let mut npz = NpzIn::new(&bytes).unwrap();
        let a = npz.f64s("a").unwrap().rows("a", Some(3), 2).unwrap();
        let flat: Vec<u64> = a.iter().flatten().map(|x| x.to_bits()).collect();
        assert_eq!(flat, floats.map(f64::to_bits));
        assert_eq!(npz.usizes("n").unwrap().list("n", Some(2)).unwrap(), [1, 7]);
        assert_eq!(npz.f64s("s").unwrap().scalar("s").unwrap(), 0.5);
        assert_eq!(
            npz.strings("names").unwrap().list("names", None).unwrap(),
            ["α/β", ""]
        );
        assert_eq!(
            npz.bools("b").unwrap().rows("b", None, 2).unwrap(),
            [[true, false]]
        );
        let e = npz.f64s("n").err().unwrap();
        assert!(e.contains("array 'n'"), "{e}");
        let e = npz.f64s("a").unwrap().list("a", None).err().unwrap();
        assert!(e.contains("array 'a' has shape [3, 2]"), "{e}");
        let e = npz.f64s("z").err().unwrap();
        assert!(e.contains("array 'z': missing"), "{e}");
    }

    #[test]
    fn torn_archives_are_errors_not_panics() {
        let mut out = NpzOut::new();
        out.f64s("a", &[1000], &vec![1.0; 1000]).unwrap();
        let bytes = out.finish().unwrap();
        for cut in [0, 10, 100, 4000, bytes.len() - 30, bytes.len() - 1] {
            let torn = &bytes[..cut];
            if let Ok(mut npz) = NpzIn::new(torn) {
                let _ = npz.f64s("a").err().expect("a torn array is not read");
            }
        }
        // A header claiming more values than stored.
        let mut edited = bytes.clone();
        let at = edited.windows(4).position(|w| w == b"1000").unwrap();
        edited[at..at + 4].copy_from_slice(b"9999");
        let mut npz = NpzIn::new(&edited).unwrap();
        let e = npz.f64s("a").err().unwrap();
        assert!(e.contains("array 'a'"), "{e}");
    }
}
