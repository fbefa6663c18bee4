//! The job files of docs/scale-out.md do what the page says: the Slurm array task script
//! and the Kubernetes Indexed Job's container script, run here as 4 local processes on
//! disjoint sample ranges (as the array tasks or pods would), merged by their merge
//! scripts, give the image of one process; the directives the page relies on are there
//! (`#SBATCH --array=0-63`, `afterok` dependency; `completionMode: Indexed`, 64
//! completions, one shared volume, the merge Job).

use std::path::{Path, PathBuf};
use std::process::Command;

use prism_image::io::raw_exr::read_raw_channels;
use yaml_rust2::{Yaml, YamlLoader};

mod support;
use support::{prism, s, stderr};

fn doc_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/scale-out")
        .join(name)
}

fn cornell() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.json")
}

const RESOLUTION: &str = "24x16";
const SPP: u32 = 8;

/// How many values of the pictures of `a` and `b` (every float channel) are not
/// bit-identical, of how many.
fn picture_difference(a: &Path, b: &Path) -> (usize, usize) {
    let (fa, fb) = (read_raw_channels(a).unwrap(), read_raw_channels(b).unwrap());
    assert_eq!(
        fa.floats.keys().collect::<Vec<_>>(),
        fb.floats.keys().collect::<Vec<_>>()
    );
    let (mut differing, mut total) = (0, 0);
    for (name, va) in &fa.floats {
        for (x, y) in va.iter().zip(&fb.floats[name]) {
            total += 1;
            if x.to_bits() != y.to_bits() {
                differing += 1;
                eprintln!("{name}: {x} and {y}");
            }
        }
    }
    (differing, total)
}

fn one_process(dir: &Path) -> PathBuf {
    let whole = dir.join("whole.exr");
    let o = prism(&[
        "render",
        s(&cornell()),
        "-o",
        s(&whole),
        "--resolution",
        RESOLUTION,
        "--spp",
        &SPP.to_string(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    whole
}

fn check_ok(o: &std::process::Output, what: &str) {
    assert!(
        o.status.success(),
        "{what}: {}\n{}",
        String::from_utf8_lossy(&o.stdout),
        stderr(o)
    );
}

#[test]
fn the_slurm_array_script_on_four_local_processes_merges_into_one_render() {
    let dir = tempfile::tempdir().unwrap();
    let parts = dir.path().join("parts");
    let spawn = |task: u32| {
        Command::new("bash")
            .arg(doc_file("slurm-render.sh"))
            .current_dir(dir.path())
            .env("SLURM_ARRAY_TASK_ID", task.to_string())
            .env("SLURM_ARRAY_TASK_COUNT", "4")
            .env_remove("SLURM_CPUS_PER_TASK")
            .env("SCENE", cornell())
            .env("SPP", SPP.to_string())
            .env("OUT", &parts)
            .env("PRISM", env!("CARGO_BIN_EXE_prism"))
            .env(
                "PRISM_ARGS",
                format!("--resolution {RESOLUTION} --threads 1"),
            )
            .spawn()
            .unwrap()
    };
    // Four processes at once, as the array's tasks (or `parallel -j 4`) run them.
    let children: Vec<_> = (0..4).map(spawn).collect();
    for (task, child) in children.into_iter().enumerate() {
        check_ok(&child.wait_with_output().unwrap(), &format!("task {task}"));
    }
    let final_image = dir.path().join("final.exr");
    let o = Command::new("bash")
        .arg(doc_file("slurm-merge.sh"))
        .current_dir(dir.path())
        .env("OUT", &parts)
        .env("TASKS", "4")
        .env("FINAL", &final_image)
        .env("PRISM", env!("CARGO_BIN_EXE_prism"))
        .output()
        .unwrap();
    check_ok(&o, "merge");
    let header = read_raw_channels(&final_image).unwrap().text;
    assert_eq!(header["prism:ranges_done"], "0..2,2..4,4..6,6..8");
    assert_eq!(header["prism:complete"], "true");
    let whole = one_process(dir.path());
    let (differing, total) = picture_difference(&whole, &final_image);
    // Exact sums: four processes give one process's picture bit for bit.
    assert_eq!(
        differing, 0,
        "{differing} of {total} values differ from one process"
    );
}

fn yaml(name: &str) -> Yaml {
    let text = std::fs::read_to_string(doc_file(name)).unwrap();
    let mut docs = YamlLoader::load_from_str(&text)
        .unwrap_or_else(|e| panic!("{name} is not valid YAML: {e}"));
    assert_eq!(docs.len(), 1, "{name}: one document");
    docs.remove(0)
}

/// The first container's shell script (`command: [/bin/sh, -c]`, `args: [script]`).
fn container_script(job: &Yaml, name: &str) -> String {
    let container = &job["spec"]["template"]["spec"]["containers"][0];
    let command: Vec<&str> = container["command"]
        .as_vec()
        .unwrap_or_else(|| panic!("{name}: no command"))
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(command, ["/bin/sh", "-c"], "{name}");
    container["args"][0].as_str().unwrap().to_string()
}

fn env_value(job: &Yaml, var: &str) -> String {
    let container = &job["spec"]["template"]["spec"]["containers"][0];
    container["env"]
        .as_vec()
        .unwrap()
        .iter()
        .find(|e| e["name"].as_str() == Some(var))
        .and_then(|e| e["value"].as_str())
        .unwrap_or_else(|| panic!("no env {var}"))
        .to_string()
}

#[test]
fn the_kubernetes_jobs_parse_and_their_scripts_merge_into_one_render() {
    let render = yaml("k8s-render-job.yaml");
    let merge = yaml("k8s-merge-job.yaml");
    for (job, name) in [(&render, "prism-render"), (&merge, "prism-merge")] {
        assert_eq!(job["apiVersion"].as_str(), Some("batch/v1"));
        assert_eq!(job["kind"].as_str(), Some("Job"));
        assert_eq!(job["metadata"]["name"].as_str(), Some(name));
        let pod = &job["spec"]["template"]["spec"];
        assert_eq!(pod["restartPolicy"].as_str(), Some("Never"));
        // One shared volume, mounted where the scripts read and write.
        assert_eq!(
            pod["volumes"][0]["persistentVolumeClaim"]["claimName"].as_str(),
            Some("prism-work")
        );
        assert_eq!(
            pod["containers"][0]["volumeMounts"][0]["mountPath"].as_str(),
            Some("/work")
        );
        assert_eq!(env_value(job, "WORK"), "/work");
    }
    assert_eq!(render["spec"]["completionMode"].as_str(), Some("Indexed"));
    assert_eq!(render["spec"]["completions"].as_i64(), Some(64));
    assert_eq!(render["spec"]["parallelism"].as_i64(), Some(64));
    assert_eq!(env_value(&render, "PARTS"), "64");
    assert_eq!(env_value(&merge, "PARTS"), "64");
    let render_script = container_script(&render, "render");
    assert!(render_script.contains("JOB_COMPLETION_INDEX"));
    let merge_script = container_script(&merge, "merge");

    // The container scripts themselves, run by sh as four pods would (the volume a folder).
    let dir = tempfile::tempdir().unwrap();
    let run = |script: &str, index: Option<u32>| {
        let mut command = Command::new("/bin/sh");
        command
            .arg("-c")
            .arg(script)
            .env("WORK", dir.path())
            .env("SCENE", cornell())
            .env("SPP", SPP.to_string())
            .env("PARTS", "4")
            .env("PRISM", env!("CARGO_BIN_EXE_prism"))
            .env(
                "PRISM_ARGS",
                format!("--resolution {RESOLUTION} --threads 1"),
            );
        if let Some(i) = index {
            command.env("JOB_COMPLETION_INDEX", i.to_string());
        }
        command
    };
    let pods: Vec<_> = (0..4)
        .map(|i| run(&render_script, Some(i)).spawn().unwrap())
        .collect();
    for (i, pod) in pods.into_iter().enumerate() {
        check_ok(&pod.wait_with_output().unwrap(), &format!("pod {i}"));
    }
    check_ok(&run(&merge_script, None).output().unwrap(), "merge pod");
    let final_image = dir.path().join("final.exr");
    let whole = one_process(dir.path());
    let (differing, total) = picture_difference(&whole, &final_image);
    assert_eq!(
        differing, 0,
        "{differing} of {total} values differ from one process"
    );
}

#[test]
fn the_slurm_scripts_carry_the_directives_the_page_relies_on() {
    let render = std::fs::read_to_string(doc_file("slurm-render.sh")).unwrap();
    let directives: Vec<&str> = render
        .lines()
        .filter_map(|l| l.strip_prefix("#SBATCH "))
        .collect();
    for wanted in ["--array=0-63", "--requeue", "--signal=B:TERM@300"] {
        assert!(
            directives.contains(&wanted),
            "slurm-render.sh lacks #SBATCH {wanted}"
        );
    }
    // Directives end at the first command (sbatch stops reading them there).
    let first_command = render
        .lines()
        .position(|l| !l.is_empty() && !l.starts_with('#'))
        .unwrap();
    let lines: Vec<&str> = render.lines().collect();
    let last_directive = lines
        .iter()
        .rposition(|l| l.starts_with("#SBATCH"))
        .unwrap();
    assert!(last_directive < first_command);
    for var in ["SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT"] {
        assert!(render.contains(var), "slurm-render.sh does not read {var}");
    }
    let submit = std::fs::read_to_string(doc_file("slurm-submit.sh")).unwrap();
    assert!(submit.contains("sbatch --parsable --array=0-63 slurm-render.sh"));
    assert!(submit.contains("--dependency=afterok:"));
    assert!(submit.contains("slurm-merge.sh"));
    let merge = std::fs::read_to_string(doc_file("slurm-merge.sh")).unwrap();
    assert!(merge.contains("merge \"${parts[@]}\""));
    // Every script parses (bash -n reads without running).
    for name in ["slurm-render.sh", "slurm-merge.sh", "slurm-submit.sh"] {
        let o = Command::new("bash")
            .arg("-n")
            .arg(doc_file(name))
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
}

#[test]
fn the_gnu_parallel_line_of_the_page_renders_and_merges() {
    // GNU parallel runs its command through a shell with {} replaced by each argument;
    // here sh does the same for the page's line, on a tiny film.
    let page =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scale-out.md"))
            .unwrap();
    let line = page
        .lines()
        .find(|l| l.starts_with("parallel -j 4 '"))
        .expect("the parallel line");
    let command = line
        .trim_start_matches("parallel -j 4 '")
        .split("' ::: ")
        .next()
        .unwrap();
    let args: Vec<&str> = line.split("' ::: ").nth(1).unwrap().split(' ').collect();
    assert_eq!(args[..4], ["0", "1", "2", "3"]);
    let merge_line = page
        .lines()
        .find(|l| l.trim_start().starts_with("&& prism merge"))
        .unwrap()
        .trim_start()
        .trim_start_matches("&& ");
    let dir = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_prism");
    let local = |c: &str| {
        c.replacen("prism ", &format!("{bin} "), 1).replace(
            "scene.json",
            &format!("{} --resolution 12x8", cornell().display()),
        )
    };
    let jobs: Vec<_> = args[..4]
        .iter()
        .map(|i| {
            Command::new("/bin/sh")
                .arg("-c")
                .arg(local(&command.replace("{}", i)))
                .current_dir(dir.path())
                .spawn()
                .unwrap()
        })
        .collect();
    for job in jobs {
        check_ok(&job.wait_with_output().unwrap(), "parallel job");
    }
    let o = Command::new("/bin/sh")
        .arg("-c")
        .arg(local(merge_line))
        .current_dir(dir.path())
        .output()
        .unwrap();
    check_ok(&o, "merge");
    let header = read_raw_channels(&dir.path().join("final.exr"))
        .unwrap()
        .text;
    assert_eq!(
        header["prism:ranges_done"],
        "0..128,128..256,256..384,384..512"
    );
}
