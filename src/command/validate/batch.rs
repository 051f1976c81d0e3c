//! `velvet validate`'s runner over many inputs, as `command/migrate/batch.rs` is migrate's (one
//! document is validated by [`crate::validate`]): find the asset files (with `--shard`, one part of
//! them; see [`crate::asset::discover`]), give each the configuration
//! found for it (see [`crate::config`]), leave out excluded files, validate the rest in
//! parallel, and decide whether the run failed. A configuration error stops the run before any
//! file is read: a broken velvet.toml is a usage error, not a finding.
//!
//! Files are validated in parallel and each report is handed on in input order as soon as it
//! and those before it are done, while the pool works on the files after it (see
//! [`in_input_order`]): a run over ten thousand files holds a window of reports, not ten
//! thousand, and writing a report never leaves a core idle.

use crate::asset::discover::{self, Shard};
use crate::config::{ConfigError, Resolver};
use crate::diagnostics::Settings;
use crate::validate::{FileReport, Validator};
use std::path::{Path, PathBuf};

/// What a run produced.
#[derive(Debug)]
pub struct Outcome {
    /// One report per file checked (folders that could not be read included), in input order.
    pub reports: Vec<FileReport>,
    /// Files left out by an exclude pattern.
    pub excluded: Vec<PathBuf>,
    /// True when a report has a finding at or above its configuration's fail-on severity.
    pub failed: bool,
}

/// Validates `inputs` with the configuration `resolver` finds for each file. `progress`, when
/// given, is told the number of files and advanced as each is done.
pub fn validate(
    validator: &Validator,
    inputs: &[PathBuf],
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
) -> Result<Outcome, ConfigError> {
    let mut reports = Vec::new();
    let each = validate_each(validator, inputs, resolver, progress, &mut |r| {
        reports.push(r)
    })?;
    Ok(Outcome {
        reports,
        excluded: each.excluded,
        failed: each.failed,
    })
}

/// What a run produced besides its reports.
#[derive(Debug)]
pub struct Totals {
    /// Files left out by an exclude pattern.
    pub excluded: Vec<PathBuf>,
    /// The excluded files that were named as inputs (not found in a folder), each with the
    /// configuration that excludes it ("the exclude patterns of …"): the run says it skipped
    /// them, since whoever named them (pre-commit, a list) may expect them checked.
    pub named_excluded: Vec<(PathBuf, String)>,
    /// True when a report has a finding at or above its configuration's fail-on severity.
    pub failed: bool,
}

/// How far the pool may work ahead of the report handed on last: enough to keep every core
/// busy behind a slow file, few enough that the reports in hand stay small.
const WINDOW: usize = 256;

/// Validates like [`validate`], handing each report to `sink` in input order as soon as it and
/// those before it are done ([`in_input_order`]) instead of keeping them.
pub fn validate_each(
    validator: &Validator,
    inputs: &[PathBuf],
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
    sink: &mut (dyn FnMut(FileReport) + Send),
) -> Result<Totals, ConfigError> {
    validate_shard_each(validator, inputs, None, resolver, progress, sink)
}

/// Validates like [`validate_each`], only the files of `shard` when one is given (see
/// [`Shard`]): N runs over shards 1/N … N/N together report every file exactly once.
pub fn validate_shard_each(
    validator: &Validator,
    inputs: &[PathBuf],
    shard: Option<Shard>,
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
    sink: &mut (dyn FnMut(FileReport) + Send),
) -> Result<Totals, ConfigError> {
    let check = |file: &Path, settings: &Settings| validator.validate_file_with(file, settings);
    check_shard_each(validator, inputs, shard, resolver, progress, &check, sink)
}

/// Runs like [`validate_shard_each`], each file's report made by `check` (given the file and
/// its configuration's settings) instead of a plain validation: `velvet validate --fix`
/// checks, fixes and validates again (see `crate::fix`).
pub fn check_shard_each(
    validator: &Validator,
    inputs: &[PathBuf],
    shard: Option<Shard>,
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
    check: &(dyn Fn(&Path, &Settings) -> FileReport + Sync),
    sink: &mut (dyn FnMut(FileReport) + Send),
) -> Result<Totals, ConfigError> {
    let (found, walk_errors) = discover::find(inputs, shard);
    let mut planned = Vec::with_capacity(found.len());
    let mut excluded = Vec::new();
    let mut named_excluded = Vec::new();
    // What excluded the first file found in a folder (not named itself), if any was.
    let mut walked_excluded_by = None;
    for found in found {
        // A file named as an input is found as itself; one found in a folder is below it.
        let named = inputs.get(found.input) == Some(&found.path);
        let file = found.path;
        // Made absolute once: its configuration is searched from its folder, and its
        // exclusion read, from the same path.
        let absolute = crate::config::absolute(&file);
        let config = resolver.for_file(&absolute)?;
        if config.excludes(&absolute) {
            let by = match &config.file {
                Some(file) => format!("the exclude patterns of {}", file.display()),
                None => "the exclude patterns".to_string(),
            };
            if named {
                named_excluded.push((file.clone(), by));
            } else if walked_excluded_by.is_none() {
                walked_excluded_by = Some(by);
            }
            excluded.push(file);
        } else {
            planned.push((file, config));
        }
    }
    // A configuration may leave files out, but not every file of a folder given: the folders
    // were checked to hold assets (discover::check_inputs), and a run that checks none of them
    // must not pass (a typo'd exclude pattern would turn the gate off). Files named one by one
    // (pre-commit passes the staged files) are another matter: skipping the excluded ones is
    // what the exclude patterns are for, so a run left with nothing from them passes.
    // A shard may be left with nothing by the split alone, so only a whole run is held to it.
    if shard.is_none() && planned.is_empty() && walk_errors.is_empty() {
        if let Some(by) = walked_excluded_by {
            return Err(ConfigError::AllExcluded {
                found: excluded.len(),
                by,
            });
        }
    }
    // Every configuration is resolved before the first report goes out: a configuration error
    // stops the run with nothing written.
    let mut unreadable = Vec::with_capacity(walk_errors.len());
    for (folder, error) in walk_errors {
        let config = resolver.for_path(&folder)?;
        unreadable.push((folder, error, config));
    }
    let mut failed = false;
    for (folder, error, config) in unreadable {
        let report = validator.unreadable_folder(folder, &error, config.settings());
        failed |= report.fails(config.settings());
        sink(report);
    }
    if let Some(bar) = progress {
        // One file is shown as itself before the length would draw "0/1".
        if let [(file, _)] = planned.as_slice() {
            crate::output::show_one_file(bar, file);
        }
        bar.set_length(planned.len() as u64);
    }
    let check_one = |i: usize| {
        let (file, config) = &planned[i];
        let report = check(file, config.settings());
        let fails = report.fails(config.settings());
        if let Some(bar) = progress {
            bar.inc(1);
        }
        (report, fails)
    };
    in_input_order(planned.len(), &check_one, &mut |(report, fails)| {
        failed |= fails;
        sink(report);
    });
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    Ok(Totals {
        excluded,
        named_excluded,
        failed,
    })
}

/// Hands `work(0)`, `work(1)`, … `work(count - 1)` to `sink` in that order, each as soon as it
/// and those before it are done. The pool's threads take the indices in order and never more
/// than [`WINDOW`] past the first one not yet taken to be handed on (so at most twice that
/// many are held); whichever thread finishes the next one due hands on every one ready from
/// there, while the others work on. (Done a batch at a time, one
/// thread wrote a batch's reports while the others stood idle: a twelfth of the run on 500
/// small files.) Nothing waits but for the lock: a thread that finds the window full stops,
/// and the thread that moves the window sets as many to work again.
fn in_input_order<T: Send>(
    count: usize,
    work: &(dyn Fn(usize) -> T + Sync),
    sink: &mut (dyn FnMut(T) + Send),
) {
    use std::collections::VecDeque;
    use std::sync::{Mutex, PoisonError};
    /// The window: `slots[k]` holds work `handed + k` once it is done.
    struct Window<T> {
        handed: usize,
        /// The next index to take.
        next: usize,
        slots: VecDeque<Option<T>>,
        /// A thread is handing on: the others leave what they finish in its slot.
        handing: bool,
        /// Threads that stopped at a full window.
        stopped: usize,
    }
    let window = Mutex::new(Window {
        handed: 0,
        next: 0,
        slots: (0..WINDOW.min(count)).map(|_| None).collect(),
        handing: false,
        stopped: 0,
    });
    let sink = Mutex::new(sink);
    fn worker<'s, T: Send>(
        scope: &rayon::Scope<'s>,
        count: usize,
        window: &'s Mutex<Window<T>>,
        work: &'s (dyn Fn(usize) -> T + Sync),
        sink: &'s Mutex<&mut (dyn FnMut(T) + Send)>,
    ) {
        let lock = || window.lock().unwrap_or_else(PoisonError::into_inner);
        loop {
            let i = {
                let mut held = lock();
                if held.next >= count {
                    return;
                }
                if held.next >= held.handed + WINDOW {
                    held.stopped += 1;
                    return;
                }
                held.next += 1;
                held.next - 1
            };
            let value = work(i);
            let mut held = lock();
            let k = i - held.handed;
            held.slots[k] = Some(value);
            if k != 0 || held.handing {
                continue;
            }
            held.handing = true;
            let mut handing = sink.lock().unwrap_or_else(PoisonError::into_inner);
            loop {
                let mut ready = Vec::new();
                while let Some(Some(_)) = held.slots.front() {
                    ready.extend(held.slots.pop_front().flatten());
                    held.slots.push_back(None);
                    held.handed += 1;
                }
                if ready.is_empty() {
                    held.handing = false;
                    break;
                }
                // The window moved: the threads stopped at it go back to work.
                for _ in 0..std::mem::take(&mut held.stopped) {
                    scope.spawn(move |scope| worker(scope, count, window, work, sink));
                }
                drop(held);
                ready.into_iter().for_each(&mut **handing);
                held = lock();
            }
        }
    }
    rayon::scope(|scope| {
        for _ in 0..rayon::current_num_threads().min(count) {
            scope.spawn(|scope| worker(scope, count, &window, work, &sink));
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Work whose time varies from index to index (a slow one every so often), so that the
    /// threads finish out of order and the window fills behind the slow ones.
    fn uneven(i: usize) -> usize {
        let spins = if i.is_multiple_of(97) {
            200_000
        } else {
            (i * 7919) % 2_000
        };
        let mut x = i as u64;
        for _ in 0..spins {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
        i
    }

    fn handed_on(threads: usize, count: usize) -> Vec<usize> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        let mut handed = Vec::new();
        pool.install(|| in_input_order(count, &uneven, &mut |i| handed.push(i)));
        handed
    }

    #[test]
    fn every_work_is_handed_on_once_in_input_order_whatever_the_thread_count() {
        let count = 3 * WINDOW + 17;
        let expected: Vec<usize> = (0..count).collect();
        for threads in [1, 2, 4, 8] {
            assert_eq!(handed_on(threads, count), expected, "{threads} threads");
        }
        assert_eq!(handed_on(4, 0), Vec::<usize>::new());
        assert_eq!(handed_on(4, 1), vec![0]);
    }

    #[test]
    fn the_pool_never_works_further_ahead_than_the_window_allows() {
        // The first work is slow; without a window the other threads would finish every other
        // work meanwhile. Each work records how far it starts past the last one handed on.
        let handed = std::sync::atomic::AtomicUsize::new(0);
        let furthest = std::sync::atomic::AtomicUsize::new(0);
        let work = |i: usize| {
            if i == 0 {
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
            let ahead = i - handed.load(std::sync::atomic::Ordering::SeqCst);
            furthest.fetch_max(ahead, std::sync::atomic::Ordering::SeqCst);
            i
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .expect("a pool");
        pool.install(|| {
            in_input_order(8 * WINDOW, &work, &mut |i| {
                handed.store(i + 1, std::sync::atomic::Ordering::SeqCst);
            })
        });
        assert_eq!(handed.into_inner(), 8 * WINDOW);
        // Up to a window taken to be handed on, and a window past it.
        let furthest = furthest.into_inner();
        assert!(
            furthest < 2 * WINDOW,
            "a work started {furthest} past the last handed on"
        );
    }

    #[test]
    fn a_panic_in_a_work_reaches_the_caller_and_nothing_after_it_is_handed_on() {
        let mut handed = Vec::new();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            in_input_order(
                2 * WINDOW,
                &|i| {
                    if i == 300 {
                        panic!("work 300 fails")
                    } else {
                        uneven(i)
                    }
                },
                &mut |i| handed.push(i),
            )
        }));
        let message = outcome.expect_err("the panic is raised again");
        assert_eq!(message.downcast_ref::<&str>(), Some(&"work 300 fails"));
        assert_eq!(handed, (0..300).collect::<Vec<_>>());
    }
}
