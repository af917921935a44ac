//! Process-wide caches of pure functions' results, each with a bound (docs/architecture.md,
//! "Bounded caches"): a long-running worker rendering varied specs keeps at most the last
//! few values a cache allows, by count and by bytes, so its memory does not grow with the
//! number of specs it has seen.
//!
//! [`KeptLast`] keeps the values made last: a value asked for again is shared from the
//! cache; a new one is made outside the lock (threads do not wait on each other's work; two
//! may make the same value, which is the same, and one is kept) and goes in last, the oldest
//! going out while the bound is exceeded. A value larger than the byte bound alone is
//! returned but not kept. The values are the pure results of their keys, so what is kept
//! changes the time a call takes, never its result.

use std::collections::{HashMap, VecDeque};
use std::hash::Hash;
use std::sync::Mutex;

/// A cache of the values made last, at most `max_len` of them and `max_bytes` in all.
pub struct KeptLast<K, V> {
    kept: Mutex<Kept<K, V>>,
    max_len: usize,
    max_bytes: usize,
}

/// The values by key with their sizes, the keys oldest first, and the bytes kept.
struct Kept<K, V> {
    values: Option<HashMap<K, (V, usize)>>,
    order: VecDeque<K>,
    bytes: usize,
}

impl<K: Hash + Eq + Clone, V: Clone> KeptLast<K, V> {
    /// An empty cache keeping at most `max_len` values of `max_bytes` in all.
    pub const fn new(max_len: usize, max_bytes: usize) -> KeptLast<K, V> {
        KeptLast {
            kept: Mutex::new(Kept {
                values: None,
                order: VecDeque::new(),
                bytes: 0,
            }),
            max_len,
            max_bytes,
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Kept<K, V>> {
        self.kept.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The value of `key`: the kept one, or `make()`'s (kept if it fits; `bytes` sizes it).
    pub fn get_or_make(&self, key: K, make: impl FnOnce() -> V, bytes: impl Fn(&V) -> usize) -> V {
        if let Some((v, _)) = self.lock().values.as_ref().and_then(|m| m.get(&key)) {
            return v.clone();
        }
        let value = make();
        let size = bytes(&value);
        if size > self.max_bytes || self.max_len == 0 {
            return value;
        }
        let mut kept = self.lock();
        let kept = &mut *kept;
        let values = kept.values.get_or_insert_with(HashMap::new);
        if let Some((v, _)) = values.get(&key) {
            return v.clone(); // made meanwhile by another thread: one is kept
        }
        // Oldest first out, until the new one fits both bounds.
        while values.len() >= self.max_len || kept.bytes + size > self.max_bytes {
            let Some(old) = kept.order.pop_front() else {
                break;
            };
            if let Some((_, b)) = values.remove(&old) {
                kept.bytes -= b;
            }
        }
        values.insert(key.clone(), (value.clone(), size));
        kept.order.push_back(key);
        kept.bytes += size;
        value
    }

    /// Values kept now.
    pub fn len(&self) -> usize {
        self.lock().values.as_ref().map_or(0, HashMap::len)
    }

    /// Whether nothing is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bytes of the values kept now (as their `bytes` said when they were made).
    pub fn bytes(&self) -> usize {
        self.lock().bytes
    }

    /// The bounds: most values, most bytes.
    pub fn bounds(&self) -> (usize, usize) {
        (self.max_len, self.max_bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a naive reference (a list of the last keys that fit), over a pseudo-random
    /// sequence of keys and sizes: the same values kept, never over either bound, and every
    /// value the function's.
    #[test]
    fn keeps_the_last_values_within_both_bounds() {
        let cache: KeptLast<u64, u64> = KeptLast::new(5, 100);
        let mut reference: Vec<(u64, u64)> = Vec::new(); // (key, bytes)
        let mut state = 12345u64;
        let mut made = 0;
        for _ in 0..2000 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let key = (state >> 33) % 12;
            let size = |k: &u64| (*k * 7 % 40 + 1) as usize;
            let v = cache.get_or_make(
                key,
                || {
                    made += 1;
                    key * 1000
                },
                |v| size(&(v / 1000)),
            );
            assert_eq!(v, key * 1000);
            if !reference.iter().any(|(k, _)| *k == key) {
                let s = size(&key) as u64;
                while !reference.is_empty()
                    && (reference.len() >= 5
                        || reference.iter().map(|(_, b)| b).sum::<u64>() + s > 100)
                {
                    reference.remove(0);
                }
                reference.push((key, s));
            }
            assert!(cache.len() <= 5 && cache.bytes() <= 100);
            assert_eq!(cache.len(), reference.len());
        }
        assert!(made < 2000, "nothing was ever shared");
        // A value bigger than the byte bound is given but not kept.
        let big: KeptLast<u8, Vec<u8>> = KeptLast::new(4, 10);
        assert_eq!(big.get_or_make(1, || vec![0; 11], Vec::len).len(), 11);
        assert!(big.is_empty());
    }

    /// Every process-wide cache of the library stays within its bounds when asked for more
    /// distinct values than it keeps: the scan converters, the clutter texture fields, the
    /// gamma and Weibull quantile tables.
    #[test]
    fn the_librarys_caches_hold_their_bounds() {
        use crate::environment::clutter::{
            weibull_texture_quantile, GammaQuantile, GAMMA_TABLES, WEIBULL_TEXTURES,
        };
        use crate::products::ppi::{PpiGeometry, ScanConverter, CONVERTERS};
        use crate::signal::clutter_map::{texture_field, TEXTURE_FIELDS};
        let within = |len: usize, bytes: usize, (max_len, max_bytes): (usize, usize)| {
            assert!(
                len <= max_len && bytes <= max_bytes,
                "{len} / {bytes} over {max_len} / {max_bytes}"
            );
        };
        for k in 0..CONVERTERS.bounds().0 + 4 {
            let geometry = PpiGeometry {
                size_px: 16,
                display_range_m: 100.0 + k as f64,
                up_azimuth_rad: 0.0,
                radar_offset_m: [0.0, 0.0],
            };
            ScanConverter::for_geometry(geometry, 36, 50, 2.0);
            within(CONVERTERS.len(), CONVERTERS.bytes(), CONVERTERS.bounds());
        }
        for seed in 0..TEXTURE_FIELDS.bounds().0 as u64 + 3 {
            texture_field(seed, 400.0, 20.0);
            within(
                TEXTURE_FIELDS.len(),
                TEXTURE_FIELDS.bytes(),
                TEXTURE_FIELDS.bounds(),
            );
        }
        for k in 0..GammaQuantile::CACHE_LEN + 20 {
            GammaQuantile::for_shape(0.5 + k as f64 * 1e-3);
        }
        within(
            GAMMA_TABLES.len(),
            GAMMA_TABLES.bytes(),
            GAMMA_TABLES.bounds(),
        );
        assert_eq!(GAMMA_TABLES.len(), GammaQuantile::CACHE_LEN);
        for k in 0..WEIBULL_TEXTURES.bounds().0 + 3 {
            weibull_texture_quantile(0.8 + k as f64 * 1e-3);
        }
        within(
            WEIBULL_TEXTURES.len(),
            WEIBULL_TEXTURES.bytes(),
            WEIBULL_TEXTURES.bounds(),
        );
    }
}
