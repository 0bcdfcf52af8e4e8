//! Every command in README.md and docs/*.md runs, as a reader would type it.
//!
//! Read: every ```sh (or ```bash, ```shell) fenced block of README.md and of each docs/*.md
//! present when the test runs. A line ending in `\` continues on the next; a line starting
//! with `#` is a comment or a shown output (`# → …`) and is not run; text after an unquoted
//! `#` that starts a word is a comment.
//!
//! Run: each line whose programs are all `candela` (chained with `&&`, `||`, `;` or `|`, with
//! redirections and globs) runs through `bash -o pipefail -c` as written, with `candela` on PATH
//! being the binary under test; [`ALIASES`] turn other spellings of candela into `candela`. A
//! line that is only `cd DIR` moves the rest of its block into DIR when DIR is in the scratch
//! directory (else DIR is the reader's, and the block stays where it is).
//!
//! Where: each page runs in order in a scratch directory of its own (a page's later commands
//! read its earlier ones' outputs; pages share nothing), holding copies of [`COPIED`] (commands
//! may write beside their inputs, and the repository must stay clean), symlinks to the
//! repository's other top-level entries, and the files of [`PREPARED`]: names the docs use for
//! files of the reader's own that the repository does not have.
//!
//! Not run: the commands of [`NOT_RUN`], each with its reason. Any other program fails the
//! test, so a new command in the docs is either run here or added to that list with a reason;
//! an entry of [`NOT_RUN`], [`ALIASES`] or [`PREPARED`] that no page uses any more fails too,
//! so the lists stay the docs' own. A line that chains a command not run with a candela command
//! fails: the candela part would go unrun.
//!
//! Documented failures: a command shown being refused ends with the comment `# fails: WHY`. It
//! must exit non-zero with a message on stderr; exiting 0 fails the test.
//!
//! Time: a command over [`BUDGET`] of processor time fails the test, naming it, and so do all
//! commands together over [`TOTAL_BUDGET`], so the docs lower their samples rather than CI
//! growing slow (processor time, so that a loaded machine does not fail the test; about twice
//! the wall time on two cores); a command still running at [`KILL_AFTER`] is killed.
//!
//! A failure names the page and line, the command, its exit status and its stderr.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A documented command that takes more processor time (user + system, all its processes)
/// than this fails the test: about half a minute on two cores.
const BUDGET: Duration = Duration::from_secs(60);
/// All the documented commands together: the test stays a few minutes on two cores.
const TOTAL_BUDGET: Duration = Duration::from_secs(480);
/// A command still running after this long is killed (and fails).
const KILL_AFTER: Duration = Duration::from_secs(600);

/// Commands the docs show that this test does not run: (the command's first words, why).
const NOT_RUN: &[(&str, &str)] = &[(
    "bash scripts/test.sh",
    "CI itself: the script runs this test",
)];

/// Other spellings of the candela command: (the spelling, why it is the binary under test).
const ALIASES: &[(&str, &str)] = &[(
    "cargo run --release --",
    "the release build of this binary; the test profile's build runs it",
)];

/// Directories copied into each scratch directory rather than linked: scenes name files
/// relative to themselves, and a command may write beside its input.
const COPIED: &[&str] = &["scenes", "data", "examples"];

/// Files made in each scratch directory: (name, why).
const PREPARED: &[(&str, &str)] = &[];

fn prepare_file(name: &str, _dir: &Path) {
    panic!("PREPARED names {name} but prepare_file does not make it")
}

/// One logical line of a shell block: its text (continuations joined) and where it starts.
struct DocLine {
    page: String,
    line: usize,
    text: String,
}

impl DocLine {
    fn place(&self) -> String {
        format!("{}:{}", self.page, self.line)
    }
}

/// The logical lines of each ```sh block of `text`, block by block.
fn shell_blocks(page: &str, text: &str) -> Vec<Vec<DocLine>> {
    let mut blocks = Vec::new();
    let mut current: Option<Vec<DocLine>> = None;
    let mut pending: Option<DocLine> = None;
    for (i, raw) in text.lines().enumerate() {
        let fence = raw.trim_start();
        if let Some(tag) = fence.strip_prefix("```") {
            match current.take() {
                Some(block) => blocks.push(block),
                None if ["sh", "bash", "shell"].contains(&tag.trim()) => current = Some(Vec::new()),
                None => {}
            }
            continue;
        }
        let Some(block) = current.as_mut() else {
            continue;
        };
        let mut line = pending.take().unwrap_or(DocLine {
            page: page.to_string(),
            line: i + 1,
            text: String::new(),
        });
        match raw.trim_end().strip_suffix('\\') {
            Some(head) => {
                line.text += head;
                line.text += " ";
                pending = Some(line);
            }
            None => {
                line.text += raw;
                block.push(line);
            }
        }
    }
    blocks
}

/// Lines of `text`'s other fenced blocks (```text, untagged, …) that are candela commands: a
/// command shown outside a ```sh block would go unrun.
fn commands_outside_shell_blocks(page: &str, text: &str) -> Vec<String> {
    let mut inside: Option<bool> = None; // Some(is a shell block) within a fence
    let mut stray = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim_start();
        if let Some(tag) = line.strip_prefix("```") {
            inside = match inside {
                Some(_) => None,
                None => Some(["sh", "bash", "shell"].contains(&tag.trim())),
            };
        } else if inside == Some(false) && is_candela_command(line) {
            stray.push(format!(
                "{page}:{}: `{}` is in a fenced block other than ```sh, where it would go \
                 unrun: show it in a ```sh block",
                i + 1,
                line.trim_end()
            ));
        }
    }
    stray
}

/// `candela SUBCOMMAND …`, a subcommand being a lowercase word; not a synopsis (`[OPTION]`,
/// `a|b`, or a placeholder in capitals such as `VALUE`).
fn is_candela_command(line: &str) -> bool {
    let placeholder = |w: &str| w.len() > 1 && w.chars().all(|c| c.is_ascii_uppercase());
    let synopsis = line.contains(['[', '|']) || line.split_whitespace().any(placeholder);
    let mut words = line.split_whitespace();
    !synopsis
        && words.next() == Some("candela")
        && words
            .next()
            .is_some_and(|w| w.chars().all(|c| c.is_ascii_lowercase() || c == '-'))
}

/// A shell word or operator of a line, quotes removed.
#[derive(Debug, PartialEq)]
enum Token {
    Word(String),
    /// `&&`, `||`, `;`, `|`, `&`: the end of one command.
    Separator,
    /// `>`, `>>`, `<`, `2>`, …: the next word is a file, not an argument.
    Redirect,
}

/// The tokens of `code` and its trailing comment (after an unquoted `#` starting a word).
fn tokenize(code: &str) -> (Vec<Token>, Option<String>) {
    let mut tokens = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut chars = code.char_indices().peekable();
    let flush = |tokens: &mut Vec<Token>, word: &mut String, in_word: &mut bool| {
        if *in_word {
            tokens.push(Token::Word(std::mem::take(word)));
            *in_word = false;
        }
    };
    while let Some((at, c)) = chars.next() {
        match c {
            '#' if !in_word => return (tokens, Some(code[at + 1..].trim().to_string())),
            '\'' | '"' => {
                in_word = true;
                for (_, q) in chars.by_ref() {
                    if q == c {
                        break;
                    }
                    word.push(q);
                }
            }
            '\\' => {
                in_word = true;
                if let Some((_, e)) = chars.next() {
                    word.push(e);
                }
            }
            '&' | '|' | ';' => {
                flush(&mut tokens, &mut word, &mut in_word);
                if chars.peek().map(|&(_, n)| n) == Some(c) {
                    chars.next();
                }
                tokens.push(Token::Separator);
            }
            '>' | '<' => {
                // `2>` and `&>`: the digits belong to the redirection.
                if word.chars().all(|d| d.is_ascii_digit()) {
                    word.clear();
                    in_word = false;
                }
                flush(&mut tokens, &mut word, &mut in_word);
                while chars.peek().is_some_and(|&(_, n)| n == '>' || n == '&') {
                    chars.next();
                }
                tokens.push(Token::Redirect);
            }
            c if c.is_whitespace() => flush(&mut tokens, &mut word, &mut in_word),
            c => {
                in_word = true;
                word.push(c);
            }
        }
    }
    flush(&mut tokens, &mut word, &mut in_word);
    (tokens, None)
}

/// The argument words of each command of a line: environment assignments (`A=b cmd`) and
/// redirections with their files left out.
fn commands(tokens: &[Token]) -> Vec<Vec<String>> {
    let mut out = vec![Vec::new()];
    let mut redirected = false;
    for t in tokens {
        let cmd = out.last_mut().unwrap();
        match t {
            Token::Separator => out.push(Vec::new()),
            Token::Redirect => redirected = true,
            Token::Word(_) if redirected => redirected = false,
            Token::Word(w) if cmd.is_empty() && is_assignment(w) => {}
            Token::Word(w) => cmd.push(w.clone()),
        }
    }
    out.retain(|c| !c.is_empty());
    out
}

fn is_assignment(word: &str) -> bool {
    word.split_once('=').is_some_and(|(name, _)| {
        !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
    })
}

fn starts_with_words(cmd: &[String], prefix: &str) -> bool {
    let words: Vec<&str> = prefix.split_whitespace().collect();
    cmd.len() >= words.len() && cmd.iter().zip(&words).all(|(a, b)| a == b)
}

/// What the test does with one logical line.
#[derive(Debug, PartialEq)]
enum Plan {
    /// Blank, or only a comment or a shown output.
    Nothing,
    /// Run through bash; `expect_failure` when marked `# fails: …`.
    Run { code: String, expect_failure: bool },
    /// `cd DIR` alone on its line.
    Cd(String),
    /// A command of [`NOT_RUN`] (its index).
    NotRun(usize),
    /// Refused: why.
    Refused(String),
}

/// Decides what to do with `text`, recording which [`ALIASES`] entries it used in `aliases_used`.
fn plan(text: &str, aliases_used: &mut [bool]) -> Plan {
    let mut code = text.trim().to_string();
    if code.is_empty() || code.starts_with('#') {
        return Plan::Nothing;
    }
    for (i, (spelling, _)) in ALIASES.iter().enumerate() {
        if code.contains(spelling) {
            code = code.replace(spelling, "candela");
            aliases_used[i] = true;
        }
    }
    let (tokens, comment) = tokenize(&code);
    let cmds = commands(&tokens);
    let expect_failure = comment.is_some_and(|c| c.starts_with("fails:"));
    if let [cd] = cmds.as_slice() {
        if cd[0] == "cd" && cd.len() == 2 {
            return Plan::Cd(cd[1].clone());
        }
    }
    let not_run: Vec<usize> = cmds
        .iter()
        .filter_map(|c| NOT_RUN.iter().position(|(p, _)| starts_with_words(c, p)))
        .collect();
    let unknown: Vec<&Vec<String>> = cmds
        .iter()
        .filter(|c| !["candela", "cd"].contains(&c[0].as_str()))
        .filter(|c| !NOT_RUN.iter().any(|(p, _)| starts_with_words(c, p)))
        .collect();
    let runs_candela = cmds.iter().any(|c| c[0] == "candela");
    if let Some(c) = unknown.first() {
        Plan::Refused(format!(
            "`{}` is neither candela nor in NOT_RUN: run it here or list it there with a reason",
            c.join(" ")
        ))
    } else if !not_run.is_empty() && runs_candela {
        Plan::Refused(
            "chains a command of NOT_RUN with a candela command, which would go unrun: \
             put them on lines of their own"
                .into(),
        )
    } else if let Some(&i) = not_run.first() {
        Plan::NotRun(i)
    } else {
        Plan::Run {
            code,
            expect_failure,
        }
    }
}

/// A scratch directory for one page: copies of [`COPIED`], links to the rest of the
/// repository's top level, the [`PREPARED`] files.
fn scratch(repo: &Path) -> tempfile::TempDir {
    let dir = tempfile::Builder::new()
        .prefix("candela-docs-")
        .tempdir()
        .unwrap();
    for entry in std::fs::read_dir(repo).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name();
        let name = name.to_str().unwrap();
        if name.starts_with('.') || name == "target" {
            continue;
        }
        let to = dir.path().join(name);
        if COPIED.contains(&name) {
            copy_tree(&entry.path(), &to);
        } else {
            std::os::unix::fs::symlink(entry.path(), &to).unwrap();
        }
    }
    for (name, _) in PREPARED {
        prepare_file(name, dir.path());
    }
    dir
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// A directory holding `candela`, a link to the binary under test, to put first on PATH.
fn bin_dir() -> tempfile::TempDir {
    let dir = tempfile::Builder::new()
        .prefix("candela-docs-bin-")
        .tempdir()
        .unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_candela"), dir.path().join("candela")).unwrap();
    dir
}

/// How one run went.
struct Outcome {
    /// None when killed at [`KILL_AFTER`].
    status: Option<std::process::ExitStatus>,
    stderr: String,
    /// Wall time.
    took: Duration,
    /// Processor time of the command's processes.
    cpu: Duration,
}

/// Runs `code` through bash in `cwd`, `bin` first on PATH; stdout and stderr go to files in
/// `logs` (pipes could fill while the test waits).
fn run(code: &str, cwd: &Path, bin: &Path, logs: &Path) -> Outcome {
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let (out, err) = (logs.join("stdout"), logs.join("stderr"));
    let cpu_before = children_cpu();
    let start = Instant::now();
    let mut child = {
        use std::os::unix::process::CommandExt;
        Command::new("bash")
            .args(["-o", "pipefail", "-c", code])
            .current_dir(cwd)
            .env("PATH", path)
            .stdin(Stdio::null())
            .stdout(std::fs::File::create(&out).unwrap())
            .stderr(std::fs::File::create(&err).unwrap())
            .process_group(0)
            .spawn()
            .expect("run bash")
    };
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > KILL_AFTER {
            kill_group(child.id());
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let took = start.elapsed();
    let cpu = children_cpu().saturating_sub(cpu_before);
    let stderr = String::from_utf8_lossy(&std::fs::read(&err).unwrap()).into_owned();
    Outcome {
        status,
        stderr,
        took,
        cpu,
    }
}

/// User + system time of this process's waited-for descendants (bash and what it ran, once
/// waited for; this test's only children are the commands it runs one at a time).
fn children_cpu() -> Duration {
    // SAFETY: getrusage writes one rusage into the zeroed struct it is given.
    let usage = unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        assert_eq!(libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage), 0);
        usage
    };
    let time = |t: libc::timeval| Duration::new(t.tv_sec as u64, t.tv_usec as u32 * 1000);
    time(usage.ru_utime) + time(usage.ru_stime)
}

/// Kills the process group `pid` leads (bash and the commands it started).
fn kill_group(pid: u32) {
    let _ = Command::new("kill")
        .args(["-KILL", "--", &format!("-{pid}")])
        .status();
}

/// Why `outcome` of the line at `line` is a failure, if it is one.
fn judge(line: &DocLine, code: &str, expect_failure: bool, o: &Outcome) -> Option<String> {
    let why = match o.status {
        None => format!("killed after {} s", KILL_AFTER.as_secs()),
        Some(s) if expect_failure && s.success() => {
            "exited 0, but is marked `# fails:`".to_string()
        }
        Some(_) if expect_failure && o.stderr.trim().is_empty() => {
            "failed as marked, but with no message on stderr".to_string()
        }
        Some(s) if !expect_failure && !s.success() => format!("exited with {s}"),
        Some(_) if o.cpu > BUDGET => format!(
            "took {:.0} s of processor time ({:.0} s wall), over the {} s budget: lower its \
             samples in the docs",
            o.cpu.as_secs_f64(),
            o.took.as_secs_f64(),
            BUDGET.as_secs()
        ),
        Some(_) => return None,
    };
    Some(format!(
        "{}: `{code}`\n  {why}\n{}",
        line.place(),
        indent(tail(&o.stderr, 40))
    ))
}

fn tail(text: &str, lines: usize) -> String {
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}

fn indent(text: String) -> String {
    text.lines().map(|l| format!("    | {l}\n")).collect()
}

/// Everything the pages did: failures, timings and which list entries were used.
#[derive(Default)]
struct Tally {
    failures: Vec<String>,
    /// (page:line, wall time, processor time) of each command run.
    timings: Vec<(String, Duration, Duration)>,
    not_run: Vec<Vec<String>>,
    aliases_used: Vec<bool>,
    /// Which [`PREPARED`] files a command run names.
    prepared_used: Vec<bool>,
}

fn note_prepared(code: &str, used: &mut [bool]) {
    for cmd in commands(&tokenize(code).0) {
        for (i, (name, _)) in PREPARED.iter().enumerate() {
            used[i] |= cmd.iter().any(|w| w == name);
        }
    }
}

/// Runs the blocks of one page in a fresh scratch directory.
fn run_page(repo: &Path, page: &str, bin: &Path, tally: &mut Tally) {
    let text = std::fs::read_to_string(repo.join(page)).unwrap();
    tally
        .failures
        .extend(commands_outside_shell_blocks(page, &text));
    let blocks = shell_blocks(page, &text);
    if blocks.is_empty() {
        return;
    }
    let dir = scratch(repo);
    let logs = tempfile::tempdir().unwrap();
    for block in blocks {
        let mut cwd = dir.path().to_path_buf();
        for line in block {
            match plan(&line.text, &mut tally.aliases_used) {
                Plan::Nothing => {}
                Plan::Cd(to) => cwd = change_dir(&cwd, &to, dir.path()),
                Plan::NotRun(i) => tally.not_run[i].push(line.place()),
                Plan::Refused(why) => tally.failures.push(format!("{}: {why}", line.place())),
                Plan::Run {
                    code,
                    expect_failure,
                } => {
                    note_prepared(&code, &mut tally.prepared_used);
                    let o = run(&code, &cwd, bin, logs.path());
                    eprintln!(
                        "{:>6.1} s cpu {:>6.1} s wall  {}: {code}",
                        o.cpu.as_secs_f64(),
                        o.took.as_secs_f64(),
                        line.place()
                    );
                    tally.timings.push((line.place(), o.took, o.cpu));
                    tally
                        .failures
                        .extend(judge(&line, &code, expect_failure, &o));
                }
            }
        }
    }
}

/// The directory after `cd to` from `cwd`: `to` when it is inside the scratch directory `root`,
/// else `cwd` (a directory of the reader's machine).
fn change_dir(cwd: &Path, to: &str, root: &Path) -> PathBuf {
    let target = cwd.join(to);
    match (target.canonicalize(), root.canonicalize()) {
        (Ok(t), Ok(r)) if t.is_dir() && t.starts_with(&r) => t,
        _ => cwd.to_path_buf(),
    }
}

/// README.md and docs/*.md, sorted.
fn pages(repo: &Path) -> Vec<String> {
    let mut pages: Vec<String> = std::fs::read_dir(repo.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md"))
        .map(|n| format!("docs/{n}"))
        .collect();
    pages.sort();
    pages.insert(0, "README.md".into());
    pages
}

/// Entries of the lists that no page uses any more.
fn stale_entries(tally: &Tally) -> Vec<String> {
    let mut stale = Vec::new();
    for (i, (cmd, _)) in NOT_RUN.iter().enumerate() {
        if tally.not_run[i].is_empty() {
            stale.push(format!(
                "NOT_RUN lists `{cmd}`, which no page shows any more"
            ));
        }
    }
    for (i, (spelling, _)) in ALIASES.iter().enumerate() {
        if !tally.aliases_used[i] {
            stale.push(format!(
                "ALIASES lists `{spelling}`, which no page shows any more"
            ));
        }
    }
    for (i, (name, _)) in PREPARED.iter().enumerate() {
        if !tally.prepared_used[i] {
            stale.push(format!(
                "PREPARED makes {name}, which no command names any more"
            ));
        }
    }
    stale
}

fn total_cpu(tally: &Tally) -> Duration {
    tally.timings.iter().map(|t| t.2).sum()
}

/// The slowest commands, when all of them together are over [`TOTAL_BUDGET`].
fn over_total_budget(tally: &Tally) -> Option<String> {
    let total = total_cpu(tally);
    if total <= TOTAL_BUDGET {
        return None;
    }
    let mut slow: Vec<&(String, Duration, Duration)> = tally.timings.iter().collect();
    slow.sort_by_key(|t| std::cmp::Reverse(t.2));
    let list: Vec<String> = slow
        .iter()
        .take(5)
        .map(|(place, _, cpu)| format!("{place} ({:.0} s)", cpu.as_secs_f64()))
        .collect();
    Some(format!(
        "the commands took {:.0} s of processor time together, over the {} s budget; the \
         slowest: {}",
        total.as_secs_f64(),
        TOTAL_BUDGET.as_secs(),
        list.join(", ")
    ))
}

fn summary(tally: &Tally, wall: Duration) -> String {
    let mut s = format!(
        "{} commands run in {:.0} s ({:.0} s of processor time); not run:\n",
        tally.timings.len(),
        wall.as_secs_f64(),
        total_cpu(tally).as_secs_f64()
    );
    for (i, (cmd, why)) in NOT_RUN.iter().enumerate() {
        let _ = writeln!(s, "  {cmd} ({}): {why}", tally.not_run[i].join(", "));
    }
    s
}

#[test]
fn every_documented_command_runs() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bin = bin_dir();
    let mut tally = Tally {
        not_run: vec![Vec::new(); NOT_RUN.len()],
        aliases_used: vec![false; ALIASES.len()],
        prepared_used: vec![false; PREPARED.len()],
        ..Tally::default()
    };
    let start = Instant::now();
    for page in pages(repo) {
        run_page(repo, &page, bin.path(), &mut tally);
    }
    eprintln!("{}", summary(&tally, start.elapsed()));
    tally.failures.extend(stale_entries(&tally));
    tally.failures.extend(over_total_budget(&tally));
    assert!(
        tally.failures.is_empty(),
        "{} of the docs' commands failed:\n\n{}",
        tally.failures.len(),
        tally.failures.join("\n")
    );
}

#[test]
fn lines_are_read_as_the_shell_reads_them() {
    let mut used = vec![false; ALIASES.len()];
    let run = |code: &str, fails| Plan::Run {
        code: code.into(),
        expect_failure: fails,
    };
    let a = "candela glare x.exr --json > x.glare.json  # indices";
    assert_eq!(plan(a, &mut used), run(a, false));
    let b = "candela render bad.ron  # fails: no such file";
    assert_eq!(plan(b, &mut used), run(b, true));
    assert_eq!(plan("# → 410 lx", &mut used), Plan::Nothing);
    assert_eq!(
        plan("cd /shared/renders", &mut used),
        Plan::Cd("/shared/renders".into())
    );
    let c = "CANDELA_PYTHON=/usr/bin/python3 bash scripts/test.sh --test scenes";
    assert!(matches!(plan(c, &mut used), Plan::NotRun(_)));
    assert!(matches!(
        plan("ls -l && candela x", &mut used),
        Plan::Refused(_)
    ));
    assert!(matches!(
        plan("cargo test && candela x", &mut used),
        Plan::Refused(_)
    ));
    assert_eq!(
        plan("cargo run --release -- render s.ron", &mut used),
        run("candela render s.ron", false)
    );
    let blocks = shell_blocks(
        "p",
        "```sh\ncandela render a \\\n  --spp 4\n```\n```ron\nx\n```\n",
    );
    assert_eq!(blocks.len(), 1);
    assert_eq!(blocks[0][0].line, 2);
    assert_eq!(blocks[0][0].text, "candela render a    --spp 4");
    let stray = "```text\ncandela annual s.ron  # x\ncandela: error\n```\n```sh\ncandela x\n```\n";
    assert_eq!(commands_outside_shell_blocks("p", stray).len(), 1);
    assert!(!is_candela_command("candela convert VALUE FROM TO"));
    assert!(!is_candela_command(
        "candela probe NAME.exr X Y [--radius R]"
    ));
    assert!(is_candela_command("candela spectrum LED-B3"));
}
