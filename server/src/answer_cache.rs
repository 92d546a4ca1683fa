//! The answer cache of the solver endpoints: a solver answer is a pure
//! function of the request, the stored values its references resolved to (tools, machine,
//! material) and the output options, so the same question asked again is answered with the bytes
//! of the first answer, without a solver slot. Safe by construction: those values are part of the
//! key, so a changed tool asks a new question; a new build starts with an empty cache. Bounded by
//! bytes, least recently used first out.

use std::sync::Mutex;

use axum::body::Bytes;
use hashlink::LruCache;
use sha2::{Digest, Sha256};

/// One stored answer: the bytes exactly as first sent, and their media type.
#[derive(Clone)]
pub struct CachedAnswer {
    pub bytes: Bytes,
    pub media_type: &'static str,
}

/// Digest of a question: 32 bytes whatever the request's size.
pub type Question = [u8; 32];

/// A byte-bounded LRU of answers; `budget_bytes` 0 keeps nothing.
pub struct AnswerCache {
    budget_bytes: usize,
    entries: Mutex<Entries>,
}

impl std::fmt::Debug for AnswerCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AnswerCache").field("budget_bytes", &self.budget_bytes).finish_non_exhaustive()
    }
}

struct Entries {
    answers: LruCache<Question, CachedAnswer>,
    bytes: usize,
}

impl AnswerCache {
    /// An empty cache holding at most `budget_bytes` of answers.
    pub fn new(budget_bytes: usize) -> Self {
        Self { budget_bytes, entries: Mutex::new(Entries { answers: LruCache::new_unbounded(), bytes: 0 }) }
    }

    /// Whether the cache keeps anything.
    pub fn enabled(&self) -> bool {
        self.budget_bytes > 0
    }

    /// The digest of a question given as its parts (capability, request, resolved values,
    /// output options), each length-prefixed so that no two different part lists collide by
    /// concatenation.
    pub fn question(parts: &[&[u8]]) -> Question {
        let mut hasher = Sha256::new();
        for part in parts {
            hasher.update((part.len() as u64).to_le_bytes());
            hasher.update(part);
        }
        hasher.finalize().into()
    }

    /// The stored answer to `question`, marking it recently used.
    pub fn get(&self, question: &Question) -> Option<CachedAnswer> {
        let mut entries = self.entries.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        entries.answers.get(question).cloned()
    }

    /// Stores `answer`; an answer larger than an eighth of the budget is not kept (one large
    /// answer would push out hundreds of small ones).
    pub fn put(&self, question: Question, answer: CachedAnswer) {
        let size = answer.bytes.len();
        if size > self.budget_bytes / 8 {
            return;
        }
        let mut entries = self.entries.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(old) = entries.answers.insert(question, answer) {
            entries.bytes -= old.bytes.len();
        }
        entries.bytes += size;
        while entries.bytes > self.budget_bytes {
            match entries.answers.remove_lru() {
                Some((_, old)) => entries.bytes -= old.bytes.len(),
                None => break,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn answer(size: usize) -> CachedAnswer {
        CachedAnswer { bytes: Bytes::from(vec![b'x'; size]), media_type: "application/json" }
    }

    #[test]
    fn parts_are_length_prefixed() {
        assert_ne!(AnswerCache::question(&[b"ab", b"c"]), AnswerCache::question(&[b"a", b"bc"]));
        assert_eq!(AnswerCache::question(&[b"ab", b"c"]), AnswerCache::question(&[b"ab", b"c"]));
    }

    #[test]
    fn least_recently_used_goes_first_and_the_budget_holds() {
        let cache = AnswerCache::new(800);
        let [a, b, c] = [[1; 32], [2; 32], [3; 32]];
        cache.put(a, answer(100));
        cache.put(b, answer(100));
        assert!(cache.get(&a).is_some()); // a is now the most recent
        for i in 0..7 {
            cache.put([10 + i; 32], answer(100));
        }
        // 800 bytes hold eight answers; the ninth pushed out b, the least recently used.
        assert!(cache.get(&b).is_none());
        assert!(cache.get(&a).is_some());
        cache.put(c, answer(101)); // over an eighth of the budget: not kept
        assert!(cache.get(&c).is_none());
        let entries = cache.entries.lock().unwrap();
        assert_eq!(entries.bytes, entries.answers.iter().map(|(_, e)| e.bytes.len()).sum::<usize>());
        assert!(entries.bytes <= 800);
    }

    #[test]
    fn replacing_an_answer_counts_its_bytes_once() {
        let cache = AnswerCache::new(1000);
        cache.put([1; 32], answer(100));
        cache.put([1; 32], answer(50));
        assert_eq!(cache.entries.lock().unwrap().bytes, 50);
    }

    #[test]
    fn a_zero_budget_keeps_nothing() {
        let cache = AnswerCache::new(0);
        cache.put([1; 32], answer(1));
        assert!(!cache.enabled());
        assert!(cache.get(&[1; 32]).is_none());
    }
}
