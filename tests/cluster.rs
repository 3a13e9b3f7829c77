//! A trace and a pack split over processes (`pis-trace --shard`, `pis-pack solve` and
//! `merge`) give the bytes one process gives, resume after an interruption, and run from the
//! scheduler files of docs/cluster/ exactly as Slurm and Kubernetes would run them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};

use serde_json::Value;

fn bin(name: &str) -> PathBuf {
    match name {
        "pis-trace" => PathBuf::from(env!("CARGO_BIN_EXE_pis-trace")),
        "pis-pack" => PathBuf::from(env!("CARGO_BIN_EXE_pis-pack")),
        other => panic!("no binary {other}"),
    }
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn run(name: &str, args: &[&str]) -> Output {
    Command::new(bin(name)).args(args).output().expect("the tool runs")
}

fn ok(name: &str, args: &[&str]) -> Output {
    let out = run(name, args);
    assert!(out.status.success(), "{name} {args:?}: {}", text(&out.stderr));
    out
}

fn json(out: &Output) -> Value {
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("JSON report: {e}: {}", text(&out.stdout)))
}

fn spawn(name: &str, args: &[&str]) -> Child {
    Command::new(bin(name))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the tool starts")
}

fn wait_ok(child: Child, what: &str) -> Output {
    let out = child.wait_with_output().expect("the tool ends");
    assert!(out.status.success(), "{what}: {}", text(&out.stderr));
    out
}

/// samples/glass (a glass teapot, a silver cup and diffuse surroundings: every
/// representation pis-pack has) copied into `dir` at 48×36, 2 samples per pixel.
fn glass_copy(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/glass");
    std::fs::create_dir_all(dir).unwrap();
    for e in std::fs::read_dir(&src).unwrap().filter_map(Result::ok) {
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.join(e.file_name())).unwrap();
        }
    }
    let toml = dir.join("scene.toml");
    let mut t = std::fs::read_to_string(&toml).unwrap();
    for (from, to) in [("resolution = [160, 120]", "resolution = [48, 36]"), ("spp = 4", "spp = 2")]
    {
        assert!(t.contains(from), "samples/glass/scene.toml has no {from:?}: adapt the test");
        t = t.replacen(from, to, 1);
    }
    std::fs::write(&toml, t).unwrap();
    toml
}

/// Every file under `dir`, by path relative to it, with its bytes.
fn tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().filter_map(Result::ok) {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().display().to_string(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

fn assert_same_tree(a: &Path, b: &Path) {
    let (ta, tb) = (tree(a), tree(b));
    assert_eq!(ta.keys().collect::<Vec<_>>(), tb.keys().collect::<Vec<_>>(), "the same files");
    for (name, bytes) in &ta {
        assert!(bytes == &tb[name], "{name} differs");
    }
}

#[test]
fn a_trace_split_over_processes_is_the_set_one_process_traces_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = glass_copy(&dir.path().join("scene"));
    let scene = scene.to_str().unwrap();
    let whole = dir.path().join("whole");
    ok("pis-trace", &[scene, "-o", whole.to_str().unwrap()]);
    let set = dir.path().join("sharded");
    let s = set.to_str().unwrap();
    // Shards 0 and 2 of 3 at once, as separate processes sharing the directory.
    let a = spawn("pis-trace", &[scene, "-o", s, "--shard", "0/3", "--json"]);
    let b = spawn("pis-trace", &[scene, "-o", s, "--shard", "2/3", "--json"]);
    let (ra, rb) = (json(&wait_ok(a, "shard 0/3")), json(&wait_ok(b, "shard 2/3")));
    assert_eq!(
        (ra["points"].as_u64(), rb["points"].as_u64()),
        (Some(2), Some(1)),
        "4 views: points 0, 3 and 2"
    );
    assert_eq!((ra["complete"].as_bool(), rb["complete"].as_bool()), (Some(false), Some(false)));
    assert!(!set.join("set.json").exists(), "no set.json while a point is missing");
    let early = run("pis-trace", &["merge", s]);
    assert_eq!(early.status.code(), Some(3), "an incomplete set is an invalid input");
    assert!(
        text(&early.stderr).contains("1 of 4 points are not traced yet (points 1;"),
        "{}",
        text(&early.stderr)
    );
    // Another trace (other samples per pixel) is refused in a directory this one is writing.
    let other = run("pis-trace", &[scene, "-o", s, "--shard", "1/3", "--spp", "1"]);
    assert_eq!(other.status.code(), Some(3), "{}", text(&other.stderr));
    assert!(text(&other.stderr).contains("another trace"), "{}", text(&other.stderr));
    // An interruption: point 3's EXR written, its record not. Resuming shard 0 traces it
    // again and keeps point 0.
    std::fs::remove_file(set.join("shards/point_00003.json")).unwrap();
    let resumed = json(&ok("pis-trace", &[scene, "-o", s, "--shard", "0/3", "--resume", "--json"]));
    assert_eq!(
        (resumed["points"].as_u64(), resumed["resumed"].as_u64()),
        (Some(1), Some(1)),
        "{resumed}"
    );
    let last = json(&ok("pis-trace", &[scene, "-o", s, "--shard", "1/3", "--resume", "--json"]));
    assert_eq!(last["complete"].as_bool(), Some(true), "the last shard writes set.json");
    assert!(!set.join("shards").exists(), "the records go once the set is complete");
    assert_same_tree(&whole, &set);
    let again = json(&ok("pis-trace", &["merge", s, "--json"]));
    assert_eq!(again["already_complete"].as_bool(), Some(true));
    let done = json(&ok("pis-trace", &[scene, "-o", s, "--shard", "2/3", "--resume", "--json"]));
    assert_eq!(
        (done["points"].as_u64(), done["complete"].as_bool()),
        (Some(0), Some(true)),
        "a complete set has nothing to resume"
    );
    assert_same_tree(&whole, &set);
}

#[test]
fn a_pack_split_over_processes_writes_the_bytes_one_process_writes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = glass_copy(&dir.path().join("scene"));
    let set = dir.path().join("set");
    let s = set.to_str().unwrap();
    ok("pis-trace", &[scene.to_str().unwrap(), "-o", s]);
    let flags = ["--representation", "auto", "--ratio", "150"];
    let whole = dir.path().join("whole.pis");
    ok("pis-pack", &[&[s, "-o", whole.to_str().unwrap()][..], &flags].concat());
    let frag = dir.path().join("solved");
    let f = frag.to_str().unwrap();
    let solve = |i: &str| {
        spawn(
            "pis-pack",
            &[&["solve", s, "--shard", i, "--fragments", f, "--json"][..], &flags].concat(),
        )
    };
    let (a, b) = (solve("0/2"), solve("1/2"));
    let (ra, rb) = (json(&wait_ok(a, "solve 0/2")), json(&wait_ok(b, "solve 1/2")));
    let objects: Vec<String> = [&ra, &rb]
        .iter()
        .flat_map(|r| {
            r["objects"].as_array().unwrap().iter().map(|o| o.as_str().unwrap().to_string())
        })
        .collect();
    assert!(
        objects.iter().any(|o| o == "GlassTeapot") && objects.iter().any(|o| o == "SilverCup"),
        "{objects:?}"
    );
    let held = ra["solutions"].as_u64().unwrap() + rb["solutions"].as_u64().unwrap();
    let merged = dir.path().join("merged.pis");
    let m = json(&ok(
        "pis-pack",
        &[&["merge", s, "--fragments", f, "-o", merged.to_str().unwrap(), "--json"][..], &flags]
            .concat(),
    ));
    // The shards solve every alternative (they lack the other objects' solved figures that
    // `auto` screens by); the merge reads those the screen takes and solves nothing.
    let read = m["fragments"]["read"].as_u64().unwrap();
    assert!(
        m["fragments"]["solved"].as_u64() == Some(0) && read > 0 && read <= held,
        "every solve read from the fragments ({held} held): {}",
        m["fragments"]
    );
    assert!(
        std::fs::read(&whole).unwrap() == std::fs::read(&merged).unwrap(),
        "the merged file is the single process's, byte for byte"
    );
    // A resumed shard keeps its fragment.
    let again = json(&ok(
        "pis-pack",
        &[&["solve", s, "--shard", "1/2", "--fragments", f, "--resume", "--json"][..], &flags]
            .concat(),
    ));
    assert_eq!(again["resumed"].as_bool(), Some(true));
    // A missing shard: the merge solves its objects itself, the same bytes.
    std::fs::remove_file(Path::new(rb["fragment"].as_str().unwrap())).unwrap();
    let partial = dir.path().join("partial.pis");
    let p = json(&ok(
        "pis-pack",
        &[&["merge", s, "--fragments", f, "-o", partial.to_str().unwrap(), "--json"][..], &flags]
            .concat(),
    ));
    // It solves what the screen takes of them: at most what the shard solved.
    let solved = p["fragments"]["solved"].as_u64().unwrap();
    assert!(solved > 0 && solved <= rb["solutions"].as_u64().unwrap(), "{}", p["fragments"]);
    assert!(std::fs::read(&whole).unwrap() == std::fs::read(&partial).unwrap());
    // No fragments at all is an error that names the folder, and writes nothing.
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let none = dir.path().join("none.pis");
    let out = run(
        "pis-pack",
        &["merge", s, "--fragments", empty.to_str().unwrap(), "-o", none.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(3), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("no solve fragments") && !none.exists());
    // A damaged fragment is refused, not read.
    std::fs::write(frag.join("solve-0009-of-0010.solved"), b"PISSOLVD\x01\0\0\0\xff\xff\xff\x7f")
        .unwrap();
    let out = run("pis-pack", &["merge", s, "--fragments", f, "-o", none.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("solve-0009-of-0010.solved") && !none.exists(),
        "{}",
        text(&out.stderr)
    );
}

/// A shell script in `dir` named `name` that appends its arguments, one call per line
/// (tab-separated), to `log`, and prints `reply`.
fn fake_command(dir: &Path, name: &str, log: &Path, reply: &str) {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "#!/bin/sh\nprintf '%s\\t' \"$@\" >> '{}'\nprintf '\\n' >> '{}'\n{reply}\n",
            log.display(),
            log.display()
        ),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

fn logged(log: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(log)
        .unwrap()
        .lines()
        .map(|l| l.split('\t').filter(|w| !w.is_empty()).map(str::to_string).collect())
        .collect()
}

/// PATH with the directory of the built tools first, then `fakes`.
fn path_with(fakes: &Path) -> String {
    let tools = bin("pis-trace").parent().unwrap().to_path_buf();
    format!("{}:{}:{}", tools.display(), fakes.display(), std::env::var("PATH").unwrap_or_default())
}

fn docs_cluster() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/cluster")
}

#[test]
fn the_slurm_job_array_runs_the_shards_and_the_merge_it_submits() {
    let dir = tempfile::tempdir().unwrap();
    let scene = glass_copy(&dir.path().join("scene"));
    let work = dir.path().join("work");
    let fakes = dir.path().join("fakes");
    std::fs::create_dir_all(&fakes).unwrap();
    let log = dir.path().join("sbatch.log");
    // sbatch --parsable prints the job id: one per call, counted.
    fake_command(
        &fakes,
        "sbatch",
        &log,
        &format!("echo $((1000 + $(wc -l < '{}')))", log.display()),
    );
    let flags = "--representation auto --ratio 150";
    let env = [
        ("PIS_SCENE", scene.to_str().unwrap()),
        ("PIS_WORK", work.to_str().unwrap()),
        ("PIS_SHARDS", "2"),
        ("PIS_PACK_FLAGS", flags),
        ("PIS_NAME", "glass"),
    ];
    let slurm = docs_cluster().join("slurm");
    let out = Command::new("bash")
        .arg(slurm.join("submit.sh"))
        .envs(env)
        .env("PATH", path_with(&fakes))
        .output()
        .unwrap();
    assert!(out.status.success(), "submit.sh: {}", text(&out.stderr));
    let calls = logged(&log);
    assert_eq!(calls.len(), 3, "{calls:?}");
    // The order and the dependencies Slurm would follow.
    let script = |c: &Vec<String>| {
        Path::new(c.last().unwrap()).file_name().unwrap().to_string_lossy().into_owned()
    };
    assert_eq!(
        calls.iter().map(script).collect::<Vec<_>>(),
        ["trace.sbatch", "solve.sbatch", "merge.sbatch"]
    );
    assert!(
        calls[0].contains(&"--array=0-1".to_string())
            && calls[1].contains(&"--array=0-1".to_string()),
        "{calls:?}"
    );
    assert!(
        calls[1].contains(&"--dependency=afterok:1001".to_string())
            && calls[2].contains(&"--dependency=afterok:1002".to_string()),
        "{calls:?}"
    );
    assert!(calls.iter().all(|c| c.contains(&"--export=ALL".to_string())));
    // Each job as Slurm runs it: every array task with its index, the trace tasks at once.
    let job = |c: &Vec<String>, task: Option<usize>| {
        let mut cmd = Command::new("bash");
        cmd.arg(c.last().unwrap())
            .envs(env)
            .env("PATH", path_with(&fakes))
            .env("SLURM_CPUS_PER_TASK", "1");
        if let Some(t) = task {
            cmd.env("SLURM_ARRAY_TASK_ID", t.to_string()).env("SLURM_ARRAY_TASK_COUNT", "2");
        }
        cmd.stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped());
        cmd.spawn().unwrap()
    };
    let tasks: Vec<Child> = (0..2).map(|t| job(&calls[0], Some(t))).collect();
    for (t, task) in tasks.into_iter().enumerate() {
        wait_ok(task, &format!("trace task {t}"));
    }
    assert!(work.join("set/set.json").is_file(), "the last trace task completed the set");
    for t in 0..2 {
        wait_ok(job(&calls[1], Some(t)), &format!("solve task {t}"));
    }
    wait_ok(job(&calls[2], None), "merge");
    // The same file as one pis-pack of the set with the same flags.
    let single = dir.path().join("single.pis");
    let set = work.join("set");
    let args: Vec<&str> = [set.to_str().unwrap(), "-o", single.to_str().unwrap()]
        .into_iter()
        .chain(flags.split(' '))
        .collect();
    ok("pis-pack", &args);
    assert!(
        std::fs::read(work.join("glass.pis")).unwrap() == std::fs::read(&single).unwrap(),
        "the Slurm run writes the single process's bytes"
    );
}

/// A Job manifest of docs/cluster/kubernetes read as far as the test needs: the Indexed
/// completion mode and counts, the container's `env` values and its `/bin/sh -c` script.
struct JobFile {
    indexed: bool,
    completions: usize,
    parallelism: usize,
    env: BTreeMap<String, String>,
    script: String,
}

fn read_job(path: &Path) -> JobFile {
    let t = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = t.lines().collect();
    let field = |key: &str| -> Option<String> {
        lines
            .iter()
            .map(|l| l.trim())
            .find_map(|l| l.strip_prefix(key).map(|v| v.trim().to_string()))
    };
    let unquote = |v: &str| -> String {
        let v = v.split(" #").next().unwrap().trim();
        v.trim_matches('"').to_string()
    };
    let mut env = BTreeMap::new();
    for (i, l) in lines.iter().enumerate() {
        if let Some(name) = l.trim().strip_prefix("- name: ") {
            let name = name.split(" #").next().unwrap().trim();
            if let Some(v) = lines.get(i + 1).and_then(|n| n.trim().strip_prefix("value: ")) {
                env.insert(name.to_string(), unquote(v));
            } else if lines.get(i + 1).is_some_and(|n| n.trim() == "valueFrom:") {
                env.insert(name.to_string(), String::new());
            }
        }
    }
    assert!(
        t.contains(r#"command: ["/bin/sh", "-c"]"#),
        "{}: the container runs its script through /bin/sh -c",
        path.display()
    );
    let start = lines.iter().position(|l| l.trim() == "args:").expect("args") + 1;
    assert_eq!(lines[start].trim(), "- |", "{}: the script is one block scalar", path.display());
    let indent = |l: &str| l.len() - l.trim_start().len();
    let base = indent(lines[start]);
    let body: Vec<&str> = lines[start + 1..]
        .iter()
        .copied()
        .take_while(|l| l.trim().is_empty() || indent(l) > base)
        .collect();
    let cut = body.iter().find(|l| !l.trim().is_empty()).map_or(0, |l| indent(l));
    let script = body
        .iter()
        .map(|l| if l.len() >= cut { &l[cut..] } else { "" })
        .collect::<Vec<_>>()
        .join("\n");
    let count = |k: &str| {
        field(k).map_or(1, |v| v.parse().unwrap_or_else(|_| panic!("{}: {k} {v}", path.display())))
    };
    JobFile {
        indexed: field("completionMode:").as_deref() == Some("Indexed"),
        completions: count("completions:"),
        parallelism: count("parallelism:"),
        env,
        script,
    }
}

#[test]
fn the_kubernetes_indexed_jobs_run_the_shards_and_the_merge_they_describe() {
    let dir = tempfile::tempdir().unwrap();
    let scene = glass_copy(&dir.path().join("scene"));
    let work = dir.path().join("work");
    std::fs::create_dir_all(&work).unwrap();
    let fakes = dir.path().join("fakes");
    std::fs::create_dir_all(&fakes).unwrap();
    let log = dir.path().join("kubectl.log");
    fake_command(&fakes, "kubectl", &log, "true");
    let k8s = docs_cluster().join("kubernetes");
    let out = Command::new("bash")
        .arg(k8s.join("submit.sh"))
        .env("PATH", path_with(&fakes))
        .output()
        .unwrap();
    assert!(out.status.success(), "submit.sh: {}", text(&out.stderr));
    let calls = logged(&log);
    // Each stage applied, then waited for, before the next.
    let mut applied = Vec::new();
    for (i, c) in calls.iter().enumerate() {
        if c[0] == "apply" {
            let file = PathBuf::from(&c[2]);
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            if name != "pvc.yaml" {
                let job = std::fs::read_to_string(&file)
                    .unwrap()
                    .lines()
                    .find_map(|l| {
                        l.trim().strip_prefix("name: pis-").map(|n| format!("job/pis-{n}"))
                    })
                    .unwrap();
                assert!(
                    calls.get(i + 1).is_some_and(|w| w[0] == "wait" && w.contains(&job)),
                    "{name} is waited for ({job}) before the next: {calls:?}"
                );
                applied.push(file);
            }
        }
    }
    let names: Vec<String> =
        applied.iter().map(|f| f.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["trace-job.yaml", "solve-job.yaml", "merge-job.yaml"]);
    let mut flags = String::new();
    for file in &applied {
        let job = read_job(file);
        if job.indexed {
            let shards: usize = job.env["PIS_SHARDS"].parse().unwrap();
            assert_eq!(
                (job.completions, job.parallelism),
                (shards, shards),
                "{}: completions, parallelism and PIS_SHARDS agree",
                file.display()
            );
        } else {
            assert_eq!(job.completions, 1);
        }
        flags = job.env.get("PIS_PACK_FLAGS").cloned().unwrap_or(flags);
        // Every pod of the Job, as Kubernetes runs it: the volume is the work folder.
        let mut env = job.env.clone();
        env.insert("PIS_WORK".into(), work.display().to_string());
        env.insert("PIS_SCENE".into(), scene.display().to_string());
        env.insert("PIS_THREADS".into(), "1".into());
        let pods: Vec<Option<usize>> =
            if job.indexed { (0..job.completions).map(Some).collect() } else { vec![None] };
        for pod in pods {
            let mut cmd = Command::new("/bin/sh");
            cmd.arg("-c").arg(&job.script).envs(&env).env("PATH", path_with(&fakes));
            if let Some(i) = pod {
                cmd.env("JOB_COMPLETION_INDEX", i.to_string());
            }
            let out = cmd.output().unwrap();
            assert!(out.status.success(), "{} pod {pod:?}: {}", file.display(), text(&out.stderr));
        }
    }
    let name = read_job(&applied[2]).env.get("PIS_NAME").cloned().unwrap_or_else(|| "scene".into());
    let single = dir.path().join("single.pis");
    let set = work.join("set");
    let args: Vec<&str> = [set.to_str().unwrap(), "-o", single.to_str().unwrap()]
        .into_iter()
        .chain(flags.split_whitespace())
        .collect();
    ok("pis-pack", &args);
    assert!(
        std::fs::read(work.join(format!("{name}.pis"))).unwrap() == std::fs::read(&single).unwrap(),
        "the Kubernetes run writes the single process's bytes"
    );
}
