//! The built `photonmap` binary, run as a user runs it: [`Run`] gathers the
//! arguments, the folder and the environment, spawns it and checks the
//! outcome the test expects of it.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

/// One run of `photonmap`. It runs in the package root, as a user runs it in
/// a checkout: commands find `reference_images/` there (bench accuracy,
/// differentials and mitsuba look for their references by that relative
/// path), so a test gives every output a path in its own `TempDir`.
/// [`Run::in_dir`] runs it elsewhere.
pub struct Run {
    command: Command,
    shown: String,
    /// Files and folders the command is asked to write: a refused command
    /// must leave each one that did not exist before it ran as absent.
    outputs: Vec<PathBuf>,
}

impl Run {
    /// `photonmap ARGS`.
    pub fn new<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> Self {
        Self::of(env!("CARGO_BIN_EXE_photonmap"), args)
    }

    /// The binary at `bin` (a copy of `photonmap`) with `args`.
    pub fn of<S: AsRef<OsStr>>(bin: impl AsRef<OsStr>, args: impl IntoIterator<Item = S>) -> Self {
        let mut command = Command::new(bin);
        command.current_dir(super::root());
        Self {
            command,
            shown: "photonmap".into(),
            outputs: Vec::new(),
        }
        .args(args)
    }

    pub fn arg(mut self, arg: impl AsRef<OsStr>) -> Self {
        self.shown.push(' ');
        self.shown += &arg.as_ref().to_string_lossy();
        self.command.arg(arg);
        self
    }

    pub fn args<S: AsRef<OsStr>>(self, args: impl IntoIterator<Item = S>) -> Self {
        args.into_iter().fold(self, Run::arg)
    }

    /// A scene of scenes/ (`ring`, `variants/...`) by its file's path.
    pub fn scene(self, name: &str) -> Self {
        self.arg(super::scene_file(name))
    }

    /// `flag path` for something the command writes (`--exr`, `--out`,
    /// `--snapshots`): a refused run must not have made it.
    pub fn writing(mut self, flag: &str, path: impl AsRef<Path>) -> Self {
        self.outputs.push(path.as_ref().to_path_buf());
        self.arg(flag).arg(path.as_ref())
    }

    /// `path`, a positional argument the command writes.
    pub fn writing_arg(mut self, path: impl AsRef<Path>) -> Self {
        self.outputs.push(path.as_ref().to_path_buf());
        self.arg(path.as_ref())
    }

    /// `-o path`, an output image.
    pub fn output_to(self, path: impl AsRef<Path>) -> Self {
        self.writing("-o", path)
    }

    /// Runs in `dir` instead of the package root.
    pub fn in_dir(mut self, dir: impl AsRef<Path>) -> Self {
        self.command.current_dir(dir);
        self
    }

    /// Runs it under this umask (octal, as the shell's `umask` takes it):
    /// through `sh -c 'umask M && exec ...'`, the same program, arguments,
    /// folder and environment.
    pub fn umask(mut self, mask: u32) -> Self {
        let mut wrapped = Command::new("sh");
        wrapped
            .arg("-c")
            .arg(format!("umask {mask:03o} && exec \"$0\" \"$@\""))
            .arg(self.command.get_program())
            .args(self.command.get_args());
        if let Some(dir) = self.command.get_current_dir() {
            wrapped.current_dir(dir);
        }
        for (key, value) in self.command.get_envs() {
            match value {
                Some(v) => wrapped.env(key, v),
                None => wrapped.env_remove(key),
            };
        }
        self.command = wrapped;
        self.shown = format!("(umask {mask:03o}) {}", self.shown);
        self
    }

    pub fn env(mut self, key: &str, value: impl AsRef<OsStr>) -> Self {
        self.command.env(key, value);
        self
    }

    /// Runs it to the end, whatever the outcome.
    pub fn run(mut self) -> Output {
        self.command
            .output()
            .unwrap_or_else(|e| panic!("{}: {e}", self.shown))
    }

    /// Runs it; it must succeed (if not, its stderr says why).
    pub fn succeeds(self) -> Output {
        let shown = self.shown.clone();
        let out = self.run();
        assert!(out.status.success(), "{shown}: {}", out.stderr_text());
        out
    }

    /// What a successful run printed on stdout.
    pub fn stdout(self) -> String {
        self.succeeds().stdout_text()
    }

    /// What a successful run printed on stderr (progress, `--explain`).
    pub fn stderr(self) -> String {
        self.succeeds().stderr_text()
    }

    /// A successful run's stdout, as the JSON it must be.
    pub fn json(self) -> serde_json::Value {
        self.succeeds().json()
    }

    /// Runs it; it must fail with an error that says `says`, not panic, and
    /// write none of its outputs. Returns its stderr.
    pub fn refused_with(self, says: &str) -> String {
        let (shown, outputs) = (self.shown.clone(), self.outputs.clone());
        let absent: Vec<PathBuf> = outputs.into_iter().filter(|p| !p.exists()).collect();
        let out = self.run();
        let stderr = out.stderr_text();
        assert!(
            !out.status.success(),
            "{shown} was accepted; stderr: {stderr}"
        );
        assert!(stderr.contains(says), "{shown}: no '{says}' in: {stderr}");
        assert!(!stderr.contains("panicked"), "{shown}: {stderr}");
        for p in absent {
            assert!(!p.exists(), "{shown} wrote {}", p.display());
        }
        stderr
    }

    /// Starts it with stderr piped to the test and stdout discarded.
    pub fn spawn(mut self) -> Child {
        self.command
            .stderr(Stdio::piped())
            .stdout(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("{}: {e}", self.shown))
    }
}

/// A finished run's output as text.
pub trait Printed {
    fn stdout_text(&self) -> String;
    fn stderr_text(&self) -> String;
    /// stdout as JSON (if it is not, the error shows stdout and stderr).
    fn json(&self) -> serde_json::Value;
}

impl Printed for Output {
    fn stdout_text(&self) -> String {
        String::from_utf8_lossy(&self.stdout).into_owned()
    }

    fn stderr_text(&self) -> String {
        String::from_utf8_lossy(&self.stderr).into_owned()
    }

    fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.stdout).unwrap_or_else(|e| {
            panic!(
                "stdout is not JSON ({e}): {}\nstderr: {}",
                self.stdout_text(),
                self.stderr_text()
            )
        })
    }
}
