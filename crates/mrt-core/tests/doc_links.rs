//! Every link of the repository's Markdown files leads somewhere: a relative link names a file
//! or folder the repository holds, and a `#anchor` (in the same file or another Markdown file)
//! names one of that file's headings, as GitHub spells heading anchors. Links to the web are
//! not followed (the check runs offline), and links inside code are not links. The files are
//! read with `pulldown-cmark`, so reference links and angle-bracket links count too. The test
//! fails listing every broken link as `file:line: target (why)`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use pulldown_cmark::{Event, HeadingLevel, Options, Parser, Tag, TagEnd};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The workspace's root (this crate is `crates/mrt-core`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// Every `.md` file under `dir`, but in build output and hidden folders.
fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if !name.starts_with('.') && name != "target" && name != "node_modules" {
                markdown_files(&path, out);
            }
        } else if name.ends_with(".md") {
            out.push(path);
        }
    }
}

/// GitHub's anchor of a heading: lower case, letters, digits, `-` and `_` kept, spaces to
/// `-`, everything else dropped; the second heading of the same anchor gets `-1`, and so on.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut heading: Option<String> = None;
    for event in Parser::new_ext(text, Options::all()) {
        match event {
            Event::Start(Tag::Heading { level, .. }) if level <= HeadingLevel::H6 => {
                heading = Some(String::new());
            }
            Event::Text(t) | Event::Code(t) => {
                if let Some(h) = heading.as_mut() {
                    h.push_str(&t);
                }
            }
            Event::End(TagEnd::Heading(_)) => {
                let h = heading.take().unwrap_or_default();
                let slug: String = h
                    .to_lowercase()
                    .chars()
                    .filter_map(|c| match c {
                        ' ' => Some('-'),
                        c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
                        _ => None,
                    })
                    .collect();
                let mut unique = slug.clone();
                let mut n = 0;
                while out.contains(&unique) {
                    n += 1;
                    unique = format!("{slug}-{n}");
                }
                out.insert(unique);
            }
            _ => {}
        }
    }
    // Explicit anchors: `<a name="x">` or `<a id="x">`.
    for piece in text.split("<a ").skip(1) {
        for key in ["name=\"", "id=\""] {
            if let Some(rest) = piece.split_once(key).map(|(_, r)| r) {
                if let Some((id, _)) = rest.split_once('"') {
                    out.insert(id.to_string());
                }
            }
        }
    }
    out
}

/// The line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// Why `target`, linked from `file`, leads nowhere; `None` when it leads somewhere.
fn broken(root: &Path, file: &Path, text: &str, target: &str) -> Option<String> {
    if target.contains("://") || target.starts_with("mailto:") {
        return None;
    }
    let (path, anchor) = match target.split_once('#') {
        Some((p, a)) => (p, Some(a)),
        None => (target, None),
    };
    let dest = if path.is_empty() {
        file.to_path_buf()
    } else if let Some(abs) = path.strip_prefix('/') {
        root.join(abs)
    } else {
        file.parent().unwrap().join(path)
    };
    let Ok(dest) = dest.canonicalize() else {
        return Some("no such file".into());
    };
    if !dest.starts_with(root) {
        return Some("outside the repository".into());
    }
    let anchor = anchor.filter(|a| !a.is_empty())?;
    if dest.extension().is_some_and(|e| e == "md") {
        let other;
        let text = if dest == file {
            text
        } else {
            other = std::fs::read_to_string(&dest).unwrap();
            &other
        };
        if !anchors(text).contains(anchor) {
            return Some(format!("no heading #{anchor}"));
        }
    } else if !(anchor.starts_with('L') && anchor[1..].chars().all(|c| c.is_ascii_digit())) {
        return Some(format!("#{anchor} in a file that is not Markdown"));
    }
    None
}

#[test]
fn every_markdown_link_leads_somewhere() {
    let root = root();
    let mut files = Vec::new();
    markdown_files(&root, &mut files);
    files.sort();
    assert!(files.len() > 10, "only {} Markdown files under {}", files.len(), root.display());
    let mut bad = Vec::new();
    let mut links = 0;
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (event, range) in Parser::new_ext(&text, Options::all()).into_offset_iter() {
            let target = match event {
                Event::Start(Tag::Link { dest_url, .. } | Tag::Image { dest_url, .. }) => dest_url,
                _ => continue,
            };
            links += 1;
            if let Some(why) = broken(&root, file, &text, &target) {
                let name = file.strip_prefix(&root).unwrap().display();
                bad.push(format!("{name}:{}: {target} ({why})", line_of(&text, range.start)));
            }
        }
    }
    assert!(links > 100, "only {links} links found");
    assert!(bad.is_empty(), "{} broken links:\n{}", bad.len(), bad.join("\n"));
}

#[test]
fn anchors_are_spelled_as_github_spells_them() {
    let a = anchors(
        "# Two commands\n## The `mrt sim` command\n# Two commands\n## Size and cost (MB)\n",
    );
    let want = ["two-commands", "the-mrt-sim-command", "two-commands-1", "size-and-cost-mb"];
    assert_eq!(a, want.iter().map(|s| s.to_string()).collect());
}
