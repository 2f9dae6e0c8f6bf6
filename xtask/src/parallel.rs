//! The sweeps' references in parallel: a slice mapped in order on a few scoped threads (the
//! references are slow, brute-force answers; rayon is not worth a dependency of xtask for it).

/// `f` of every item, in order, on `threads` threads (contiguous chunks).
pub fn map<T: Sync, R: Send>(items: &[T], threads: usize, f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let chunk = items.len().div_ceil(threads.max(1)).max(1);
    let f = &f;
    std::thread::scope(|s| {
        let parts: Vec<_> = items
            .chunks(chunk)
            .map(|part| s.spawn(move || part.iter().map(f).collect::<Vec<_>>()))
            .collect();
        parts
            .into_iter()
            .flat_map(|p| p.join().expect("a reference thread panicked"))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    /// The order of the items is kept whatever the number of threads.
    #[test]
    fn keeps_the_order() {
        let items: Vec<u32> = (0..103).collect();
        for threads in [1, 2, 7, 200] {
            assert_eq!(
                super::map(&items, threads, |x| x * 2),
                (0..103).map(|x| x * 2).collect::<Vec<_>>()
            );
        }
    }
}
