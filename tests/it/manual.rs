//! The manual pages and shell completions (issue 34 §2) come from the clap definitions: a
//! page for every command that names every flag `--help` gives, and a completion script that
//! bash parses and that offers every command.

use crate::helpers;

fn subcommands() -> Vec<String> {
    // The commands as `rmapgen --help` lists them.
    let o = helpers::run(&["--help"]);
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    text.split("Commands:")
        .nth(1)
        .expect("--help lists the commands")
        .split("Options:")
        .next()
        .unwrap()
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .filter(|w| *w != "help")
        .map(String::from)
        .collect()
}

#[test]
fn every_command_has_a_page_naming_its_flags() {
    let t = helpers::tempdir();
    let out = t.path().join("man");
    let o = helpers::run(&["man", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let commands = subcommands();
    assert!(commands.len() >= 17, "{commands:?}");
    for c in &commands {
        let page = std::fs::read_to_string(out.join(format!("rmapgen-{c}.1")))
            .unwrap_or_else(|_| panic!("no page for {c}"));
        assert!(page.starts_with(".ie"), "roff: {c}");
        assert!(page.contains(&format!(".TH rmapgen-{c} 1")), "{c}");
        // Every long flag of the command's --help is on its page.
        let help = String::from_utf8_lossy(&helpers::run(&[c, "--help"]).stdout).into_owned();
        for flag in help
            .split_whitespace()
            .filter(|w| w.starts_with("--") && w.len() > 2)
            .map(|w| w.trim_end_matches(|ch: char| !ch.is_alphanumeric()))
            .filter(|w| w.len() > 2 && w[2..].chars().all(|ch| ch.is_alphanumeric() || ch == '-'))
        {
            // roff escapes '-' as '\-'.
            assert!(
                page.contains(&flag.replace('-', "\\-")),
                "{c}: {flag} is not on its page"
            );
        }
    }
    let top = std::fs::read_to_string(out.join("rmapgen.1")).unwrap();
    assert!(
        top.contains("rmapgen\\-generate(1)"),
        "the main page lists the commands"
    );
    // A second run into the same directory replaces what it wrote; a directory of someone
    // else's is refused.
    assert!(helpers::run(&["man", "--out", out.to_str().unwrap()])
        .status
        .success());
    let other = t.path().join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::write(other.join("notes.txt"), "mine").unwrap();
    let o = helpers::run(&["man", "--out", other.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(other.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn bash_completion_parses_and_offers_every_command() {
    let o = helpers::run(&["completions", "bash"]);
    assert!(o.status.success());
    let script = String::from_utf8_lossy(&o.stdout).into_owned();
    let check = std::process::Command::new("bash")
        .args(["-n", "-c", &script])
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    for c in subcommands() {
        assert!(
            script.contains(&format!(
                "rmapgen__subcmd__{}",
                c.replace('-', "__subcmd__")
            )),
            "{c}"
        );
    }
    for shell in ["zsh", "fish"] {
        let o = helpers::run(&["completions", shell]);
        assert!(o.status.success() && !o.stdout.is_empty(), "{shell}");
    }
    helpers::assert_error(&helpers::run(&["completions", "tcsh"]), "tcsh");
}
