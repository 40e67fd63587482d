//! The DCDT Agora configuration file (MRT manual §3.3.1).
//!
//! The file tells an Agora which network it lives on, which PostOffice
//! policy it uses and which channels connect it to other Agoras:
//!
//! ```text
//! <local IP addr> <multicast addr> <port>
//! PostOffice: <type>
//! [ip <mod> <lev> <local addr> <local port> <remote addr> <remote port>]*
//! [ser <mod> <lev> <device>]*
//! ```
//!
//! - The first line that is not blank or a comment is the network line. The
//!   multicast address must really be one (`224.0.0.0/4` or `ff00::/8`) and
//!   the port must be in `1..=65535`.
//! - The `PostOffice:` line is optional and may appear at most once, anywhere
//!   after the network line. Without it the Agora uses the default policy
//!   ([`PolicyKind::Pmq`]).
//! - `ip` and `ser` lines may come in any order; their order is kept.
//!   `<mod>` is `link` (forwards only locally created messages) or `bridge`
//!   (also forwards received ones); `<lev>` is a non-negative level.
//! - `#` starts a comment that runs to the end of the line. Tokens are
//!   separated by spaces or tabs; `\r\n` line endings are accepted (any
//!   carriage return separates tokens like a space).
//!
//! The example of the manual:
//!
//! ```
//! use mrt_dcdt::config::{AgoraConfig, Channel, ChannelMode, PolicyKind};
//!
//! let text = "192.168.0.1 225.0.0.1 2003\n\
//!             PostOffice: SLWB\n\
//!             ip link 0 192.168.0.1 3000 192.168.1.1 3000\n";
//! let config = AgoraConfig::parse(text, "dcdt.cfg")?;
//! assert_eq!(config.port, 2003);
//! assert_eq!(config.policy, Some(PolicyKind::Slwb));
//! assert_eq!(
//!     config.channels[0],
//!     Channel::Ip {
//!         mode: ChannelMode::Link,
//!         level: 0,
//!         local_addr: "192.168.0.1".parse()?,
//!         local_port: 3000,
//!         remote_addr: "192.168.1.1".parse()?,
//!         remote_port: 3000,
//!     }
//! );
//! // `Display` writes the file back in canonical form.
//! assert_eq!(config.to_string(), text);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;
use std::net::IpAddr;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// The keyword that starts the PostOffice line.
const POST_OFFICE: &str = "PostOffice:";
/// The known policy names, as listed in error messages.
const KNOWN_POLICIES: &str = "`SLWB`, `SLWDWCV`, `SLWSM` or `PMQ`";
const NETWORK_LINE: &str = "the network line `<local ip> <multicast addr> <port>`";
const LINE_START: &str = "`ip`, `ser` or `PostOffice:`";
const MULTICAST: &str = "a multicast address (224.0.0.0/4 or ff00::/8)";
/// Tokens longer than this are shortened in error messages.
const MAX_QUOTED_CHARS: usize = 40;

/// A parsed DCDT Agora configuration file (MRT manual §3.3.1).
///
/// `Display` writes the file back in canonical form; for a valid
/// configuration (the one [`AgoraConfig::parse`] returns, or one that obeys
/// the same rules) parsing that text gives back an equal value.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AgoraConfig {
    /// The local IP address of the Agora.
    pub local_ip: IpAddr,
    /// The multicast address used to discover other Agoras.
    pub multicast: IpAddr,
    /// The port used with the multicast address.
    pub port: u16,
    /// The PostOffice policy; `None` means the default one
    /// (see [`AgoraConfig::policy_or_default`]).
    pub policy: Option<PolicyKind>,
    /// The `ip` and `ser` channels, in file order.
    pub channels: Vec<Channel>,
}

impl AgoraConfig {
    /// Parses the text of a configuration file; `file` is only used in
    /// error messages.
    pub fn parse(text: &str, file: impl Into<PathBuf>) -> Result<AgoraConfig, ConfigError> {
        Parser { file: file.into() }.parse(text)
    }

    /// Parses the raw bytes of a configuration file; invalid UTF-8 is an
    /// error at the line and column of the first bad byte.
    pub fn parse_bytes(bytes: &[u8], file: impl Into<PathBuf>) -> Result<AgoraConfig, ConfigError> {
        let file = file.into();
        match std::str::from_utf8(bytes) {
            Ok(text) => Self::parse(text, file),
            Err(error) => {
                let valid = bytes.get(..error.valid_up_to()).unwrap_or_default();
                let prefix = std::str::from_utf8(valid).unwrap_or_default();
                let prefix = prefix.strip_prefix('\u{feff}').unwrap_or(prefix);
                let line = prefix.matches('\n').count() + 1;
                let column = prefix.rsplit('\n').next().unwrap_or_default().chars().count() + 1;
                let byte = bytes.get(error.valid_up_to()).copied().unwrap_or_default();
                Err(ConfigError::Parse {
                    file,
                    line,
                    column,
                    message: format!("expected UTF-8 text, found the invalid byte 0x{byte:02X}"),
                })
            }
        }
    }

    /// Reads and parses a configuration file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<AgoraConfig, ConfigError> {
        let path = path.as_ref();
        // Read as bytes: `parse_bytes` gives invalid UTF-8 its line.
        match mrt_core::read_bounded(path, mrt_core::MAX_CONFIG_BYTES) {
            Ok(bytes) => Self::parse_bytes(&bytes, path),
            Err(source) => Err(ConfigError::Io { file: path.to_path_buf(), source }),
        }
    }

    /// The configured PostOffice policy, or [`PolicyKind::default()`] when
    /// the file has no `PostOffice:` line.
    pub fn policy_or_default(&self) -> PolicyKind {
        self.policy.unwrap_or_default()
    }
}

impl fmt::Display for AgoraConfig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} {} {}", self.local_ip, self.multicast, self.port)?;
        if let Some(policy) = self.policy {
            writeln!(f, "{POST_OFFICE} {policy}")?;
        }
        for channel in &self.channels {
            writeln!(f, "{channel}")?;
        }
        Ok(())
    }
}

/// A PostOffice policy: how an Agora hands messages to its Members.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum PolicyKind {
    /// `SLWB`: single lock with buffer.
    Slwb,
    /// `SLWDWCV`: single lock with dispatcher with condition variable.
    Slwdwcv,
    /// `SLWSM`: single lock with single message.
    Slwsm,
    /// `PMQ`: per-member queues, MRT's faster default.
    #[default]
    Pmq,
}

impl PolicyKind {
    /// Every policy, in the order of the manual (MRT's own `PMQ` last).
    pub const ALL: [PolicyKind; 4] =
        [PolicyKind::Slwb, PolicyKind::Slwdwcv, PolicyKind::Slwsm, PolicyKind::Pmq];

    /// The name used in configuration files, e.g. `"SLWB"`.
    pub fn name(self) -> &'static str {
        match self {
            PolicyKind::Slwb => "SLWB",
            PolicyKind::Slwdwcv => "SLWDWCV",
            PolicyKind::Slwsm => "SLWSM",
            PolicyKind::Pmq => "PMQ",
        }
    }
}

impl fmt::Display for PolicyKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PolicyKind {
    type Err = UnknownPolicy;

    /// Parses a case-sensitive policy name such as `"SLWB"`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        PolicyKind::ALL
            .into_iter()
            .find(|kind| kind.name() == s)
            .ok_or_else(|| UnknownPolicy(s.to_owned()))
    }
}

/// The error of parsing a [`PolicyKind`] from an unknown name.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown PostOffice policy `{0}`, expected {KNOWN_POLICIES}")]
pub struct UnknownPolicy(pub String);

/// Which messages a channel forwards.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ChannelMode {
    /// `link`: forwards only the messages created locally.
    Link,
    /// `bridge`: also forwards the messages received from other Agoras.
    Bridge,
}

impl ChannelMode {
    /// The keyword used in configuration files: `"link"` or `"bridge"`.
    pub fn name(self) -> &'static str {
        match self {
            ChannelMode::Link => "link",
            ChannelMode::Bridge => "bridge",
        }
    }

    fn from_keyword(keyword: &str) -> Option<ChannelMode> {
        match keyword {
            "link" => Some(ChannelMode::Link),
            "bridge" => Some(ChannelMode::Bridge),
            _ => None,
        }
    }
}

impl fmt::Display for ChannelMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A channel to other Agoras: one `ip` or `ser` line of the file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Channel {
    /// An `ip` line: a point-to-point IP channel.
    Ip {
        /// Whether the channel is a link or a bridge.
        mode: ChannelMode,
        /// The level of the channel.
        level: u32,
        /// The local address to bind.
        local_addr: IpAddr,
        /// The local port to bind (1-65535).
        local_port: u16,
        /// The address of the remote Agora.
        remote_addr: IpAddr,
        /// The port of the remote Agora (1-65535).
        remote_port: u16,
    },
    /// A `ser` line: a serial channel.
    Serial {
        /// Whether the channel is a link or a bridge.
        mode: ChannelMode,
        /// The level of the channel.
        level: u32,
        /// The serial device path, e.g. `/dev/ttyS0` (one token: no
        /// whitespace, `#` or line break).
        device: String,
    },
}

impl fmt::Display for Channel {
    /// Writes the channel as one line of the configuration file (without
    /// the line break).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Channel::Ip { mode, level, local_addr, local_port, remote_addr, remote_port } => {
                write!(f, "ip {mode} {level} {local_addr} {local_port} {remote_addr} {remote_port}")
            }
            Channel::Serial { mode, level, device } => write!(f, "ser {mode} {level} {device}"),
        }
    }
}

/// An error reading or parsing an Agora configuration file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// A syntax or value error at a place in the file.
    #[error("{}:{line}:{column}: {message}", .file.display())]
    Parse {
        /// The file named by the caller.
        file: PathBuf,
        /// The 1-based line.
        line: usize,
        /// The 1-based column, in characters.
        column: usize,
        /// What was expected and what was found.
        message: String,
    },
    /// The file could not be read.
    #[error("{}: {source}", .file.display())]
    Io {
        /// The file that could not be read.
        file: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// A token and the 1-based column (in characters) where it starts.
#[derive(Clone, Copy)]
struct Token<'a> {
    column: usize,
    text: &'a str,
}

/// A line with at least one token, comments stripped.
struct Line<'a> {
    number: usize,
    tokens: Vec<Token<'a>>,
    /// The column just after the last character before any comment.
    end_column: usize,
}

/// Splits `text` into its non-empty lines of tokens.
fn tokenize(text: &str) -> impl Iterator<Item = Line<'_>> {
    text.split('\n').enumerate().filter_map(|(index, raw)| {
        let raw = raw.strip_suffix('\r').unwrap_or(raw);
        let content = raw.split('#').next().unwrap_or_default();
        let mut tokens = Vec::new();
        let mut start: Option<(usize, usize)> = None; // (byte, column)
        let mut column = 0;
        for (byte, c) in content.char_indices() {
            column += 1;
            // A stray carriage return separates tokens like a space does.
            match (matches!(c, ' ' | '\t' | '\r'), start) {
                (true, Some((from, at))) => {
                    tokens.push(Token { column: at, text: &content[from..byte] });
                    start = None;
                }
                (false, None) => start = Some((byte, column)),
                _ => {}
            }
        }
        if let Some((from, at)) = start {
            tokens.push(Token { column: at, text: &content[from..] });
        }
        (!tokens.is_empty()).then_some(Line { number: index + 1, tokens, end_column: column + 1 })
    })
}

/// The position just after the last character of `text`.
fn end_of_file(text: &str) -> (usize, usize) {
    let last = text.rsplit('\n').next().unwrap_or_default();
    let last = last.strip_suffix('\r').unwrap_or(last);
    (text.matches('\n').count() + 1, last.chars().count() + 1)
}

/// Quotes a token for an error message, escaping control characters and
/// shortening long tokens.
fn quote(token: &str) -> String {
    let mut quoted = String::from("`");
    for c in token.chars().take(MAX_QUOTED_CHARS) {
        if c.is_control() {
            quoted.extend(c.escape_default());
        } else {
            quoted.push(c);
        }
    }
    if token.chars().nth(MAX_QUOTED_CHARS).is_some() {
        quoted.push('…');
    }
    quoted.push('`');
    quoted
}

/// Parses a decimal number made of ASCII digits only (no sign).
fn digits<T: FromStr>(text: &str) -> Option<T> {
    let all_digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
    all_digits.then(|| text.parse().ok()).flatten()
}

fn parse_port(text: &str) -> Option<u16> {
    digits(text).filter(|&port: &u16| port != 0)
}

fn parse_ip(text: &str) -> Option<IpAddr> {
    text.parse().ok()
}

/// Walks through the tokens of one line, producing positioned errors.
struct Cursor<'p, 'a> {
    file: &'p Path,
    line: &'p Line<'a>,
    next: usize,
}

impl<'a> Cursor<'_, 'a> {
    fn error(&self, column: usize, message: String) -> ConfigError {
        ConfigError::Parse {
            file: self.file.to_path_buf(),
            line: self.line.number,
            column,
            message,
        }
    }

    /// The next token, or an error saying that `what` was expected.
    fn next(&mut self, what: &str) -> Result<Token<'a>, ConfigError> {
        let token = self.line.tokens.get(self.next).copied();
        self.next += 1;
        token.ok_or_else(|| {
            self.error(self.line.end_column, format!("expected {what}, found end of line"))
        })
    }

    /// Converts the next token with `convert`, or says that `what` was expected.
    fn parse<T>(
        &mut self,
        what: &str,
        convert: impl Fn(&str) -> Option<T>,
    ) -> Result<T, ConfigError> {
        let token = self.next(what)?;
        convert(token.text).ok_or_else(|| {
            self.error(token.column, format!("expected {what}, found {}", quote(token.text)))
        })
    }

    /// Checks that the line has no token left after `last`.
    fn end(&self, last: &str) -> Result<(), ConfigError> {
        match self.line.tokens.get(self.next) {
            None => Ok(()),
            Some(extra) => Err(self.error(
                extra.column,
                format!("expected end of line after {last}, found {}", quote(extra.text)),
            )),
        }
    }
}

struct Parser {
    file: PathBuf,
}

impl Parser {
    fn cursor<'p, 'a>(&'p self, line: &'p Line<'a>) -> Cursor<'p, 'a> {
        Cursor { file: &self.file, line, next: 0 }
    }

    fn parse(&self, text: &str) -> Result<AgoraConfig, ConfigError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = tokenize(text);
        let Some(network) = lines.next() else {
            let (line, column) = end_of_file(text);
            let message = format!("expected {NETWORK_LINE}, found end of file");
            return Err(ConfigError::Parse { file: self.file.clone(), line, column, message });
        };
        let (local_ip, multicast, port) = self.network_line(&network)?;
        let mut policy: Option<(PolicyKind, usize)> = None;
        let mut channels = Vec::new();
        for line in lines {
            let mut cursor = self.cursor(&line);
            let keyword = cursor.next(LINE_START)?;
            match keyword.text {
                "ip" | "ser" => channels.push(Self::channel(&mut cursor, keyword.text)?),
                text if text.starts_with(POST_OFFICE) => {
                    if let Some((_, first)) = policy {
                        let message = format!(
                            "expected at most one `{POST_OFFICE}` line, found a second one \
                             (the first is on line {first})"
                        );
                        return Err(cursor.error(keyword.column, message));
                    }
                    policy = Some((Self::policy(&mut cursor, keyword)?, line.number));
                }
                text => {
                    let message = format!("expected {LINE_START}, found {}", quote(text));
                    return Err(cursor.error(keyword.column, message));
                }
            }
        }
        Ok(AgoraConfig {
            local_ip,
            multicast,
            port,
            policy: policy.map(|(kind, _)| kind),
            channels,
        })
    }

    /// `<local IP addr> <multicast addr> <port>`
    fn network_line(&self, line: &Line<'_>) -> Result<(IpAddr, IpAddr, u16), ConfigError> {
        let mut cursor = self.cursor(line);
        if let Some(first) = line.tokens.first() {
            if matches!(first.text, "ip" | "ser") || first.text.starts_with(POST_OFFICE) {
                let message = format!("expected {NETWORK_LINE} first, found {}", quote(first.text));
                return Err(cursor.error(first.column, message));
            }
        }
        let local_ip = cursor.parse("a local IP address", parse_ip)?;
        let multicast =
            cursor.parse(MULTICAST, |text| parse_ip(text).filter(IpAddr::is_multicast))?;
        let port = cursor.parse("a port (1-65535)", parse_port)?;
        cursor.end("the port")?;
        Ok((local_ip, multicast, port))
    }

    /// The rest of `PostOffice: <type>`; `keyword` may hold the name too
    /// (`PostOffice:SLWB`).
    fn policy(cursor: &mut Cursor<'_, '_>, keyword: Token<'_>) -> Result<PolicyKind, ConfigError> {
        let what = format!("a PostOffice policy ({KNOWN_POLICIES})");
        let glued = keyword.text.strip_prefix(POST_OFFICE).unwrap_or_default();
        let name = if glued.is_empty() {
            cursor.next(&what)?
        } else {
            // `POST_OFFICE` is ASCII, so its length is also its width in characters.
            Token { column: keyword.column + POST_OFFICE.len(), text: glued }
        };
        let kind = name.text.parse().map_err(|UnknownPolicy(found)| {
            cursor.error(name.column, format!("expected {what}, found {}", quote(&found)))
        })?;
        cursor.end("the PostOffice policy")?;
        Ok(kind)
    }

    /// The rest of an `ip` or `ser` line, after the keyword.
    fn channel(cursor: &mut Cursor<'_, '_>, keyword: &str) -> Result<Channel, ConfigError> {
        let mode = cursor.parse("`link` or `bridge`", ChannelMode::from_keyword)?;
        let level = cursor.parse("a level (an integer 0-4294967295)", digits::<u32>)?;
        let channel = if keyword == "ip" {
            Channel::Ip {
                mode,
                level,
                local_addr: cursor.parse("a local IP address", parse_ip)?,
                local_port: cursor.parse("a local port (1-65535)", parse_port)?,
                remote_addr: cursor.parse("a remote IP address", parse_ip)?,
                remote_port: cursor.parse("a remote port (1-65535)", parse_port)?,
            }
        } else {
            let device = cursor.next("a serial device path such as `/dev/ttyS0`")?;
            Channel::Serial { mode, level, device: device.text.to_owned() }
        };
        cursor.end(if keyword == "ip" { "the remote port" } else { "the device" })?;
        Ok(channel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::net::{Ipv4Addr, Ipv6Addr};

    const MANUAL_EXAMPLE: &str = "192.168.0.1 225.0.0.1 2003\n\
                                  PostOffice: SLWB\n\
                                  ip link 0 192.168.0.1 3000 192.168.1.1 3000\n";

    fn parse(text: &str) -> AgoraConfig {
        match AgoraConfig::parse(text, "dcdt.cfg") {
            Ok(config) => config,
            Err(error) => panic!("{error}\n--- input ---\n{text}"),
        }
    }

    fn error(text: &str) -> String {
        match AgoraConfig::parse(text, "dcdt.cfg") {
            Ok(config) => panic!("expected an error, parsed {config:?}"),
            Err(error) => error.to_string(),
        }
    }

    fn ip(text: &str) -> IpAddr {
        match text.parse() {
            Ok(addr) => addr,
            Err(error) => panic!("bad test address {text}: {error}"),
        }
    }

    #[test]
    fn manual_example_parses_to_the_exact_model() {
        let config = parse(MANUAL_EXAMPLE);
        assert_eq!(config.local_ip, IpAddr::V4(Ipv4Addr::new(192, 168, 0, 1)));
        assert_eq!(config.multicast, IpAddr::V4(Ipv4Addr::new(225, 0, 0, 1)));
        assert_eq!(config.port, 2003);
        assert_eq!(config.policy, Some(PolicyKind::Slwb));
        assert_eq!(config.policy_or_default(), PolicyKind::Slwb);
        assert_eq!(
            config.channels,
            vec![Channel::Ip {
                mode: ChannelMode::Link,
                level: 0,
                local_addr: IpAddr::V4(Ipv4Addr::new(192, 168, 0, 1)),
                local_port: 3000,
                remote_addr: IpAddr::V4(Ipv4Addr::new(192, 168, 1, 1)),
                remote_port: 3000,
            }]
        );
        assert_eq!(config.to_string(), MANUAL_EXAMPLE);
    }

    #[test]
    fn error_messages_from_the_spec() {
        assert_eq!(
            error(""),
            "dcdt.cfg:1:1: expected the network line `<local ip> <multicast addr> <port>`, \
             found end of file"
        );
        assert_eq!(
            error("192.168.10.1 225.0.0.10 99999\n"),
            "dcdt.cfg:1:25: expected a port (1-65535), found `99999`"
        );
        assert_eq!(
            error("192.168.0.1 225.0.0.1 2003\nfoo bar\n"),
            "dcdt.cfg:2:1: expected `ip`, `ser` or `PostOffice:`, found `foo`"
        );
        assert_eq!(
            error(
                "192.168.0.1 225.0.0.1 2003\nPostOffice: SLWB\nip      lnk 0 1.2.3.4 1 1.2.3.5 2\n"
            ),
            "dcdt.cfg:3:9: expected `link` or `bridge`, found `lnk`"
        );
    }

    #[test]
    fn network_line_errors() {
        // Only comments: end of file is after the last line.
        assert_eq!(
            error("# nothing\n\n   \t\n"),
            "dcdt.cfg:4:1: expected the network line `<local ip> <multicast addr> <port>`, \
             found end of file"
        );
        assert_eq!(
            error("1.2.3.4 225.0.0.1 0"),
            "dcdt.cfg:1:19: expected a port (1-65535), found `0`"
        );
        assert_eq!(
            error("1.2.3.4 225.0.0.1 +80"),
            "dcdt.cfg:1:19: expected a port (1-65535), found `+80`"
        );
        assert_eq!(
            error("1.2.3.4 192.168.0.2 2003"),
            "dcdt.cfg:1:9: expected a multicast address (224.0.0.0/4 or ff00::/8), found `192.168.0.2`"
        );
        assert_eq!(
            error("localhost 225.0.0.1 2003"),
            "dcdt.cfg:1:1: expected a local IP address, found `localhost`"
        );
        assert_eq!(
            error("1.2.3.4"),
            "dcdt.cfg:1:8: expected a multicast address (224.0.0.0/4 or ff00::/8), found end of line"
        );
        assert_eq!(
            error("1.2.3.4 225.0.0.1   # no port\n"),
            "dcdt.cfg:1:21: expected a port (1-65535), found end of line"
        );
        assert_eq!(
            error("1.2.3.4 225.0.0.1 2003 extra"),
            "dcdt.cfg:1:24: expected end of line after the port, found `extra`"
        );
        assert_eq!(
            error("# comment\nPostOffice: SLWB\n"),
            "dcdt.cfg:2:1: expected the network line `<local ip> <multicast addr> <port>` first, \
             found `PostOffice:`"
        );
    }

    #[test]
    fn post_office_line() {
        let base = "1.2.3.4 225.0.0.1 2003\n";
        assert_eq!(parse(base).policy, None);
        assert_eq!(parse(base).policy_or_default(), PolicyKind::Pmq);
        assert_eq!(parse(&format!("{base}PostOffice:SLWSM\n")).policy, Some(PolicyKind::Slwsm));
        assert_eq!(
            parse(&format!("{base}PostOffice:\tSLWDWCV\n")).policy,
            Some(PolicyKind::Slwdwcv)
        );
        // Anywhere after the network line.
        let late = parse(&format!("{base}ser link 0 /dev/ttyS0\nPostOffice: PMQ\n"));
        assert_eq!(late.policy, Some(PolicyKind::Pmq));
        assert_eq!(late.channels.len(), 1);
        assert_eq!(
            error(&format!("{base}PostOffice: slwb\n")),
            "dcdt.cfg:2:13: expected a PostOffice policy (`SLWB`, `SLWDWCV`, `SLWSM` or `PMQ`), \
             found `slwb`"
        );
        assert_eq!(
            error(&format!("{base}PostOffice:FOO\n")),
            "dcdt.cfg:2:12: expected a PostOffice policy (`SLWB`, `SLWDWCV`, `SLWSM` or `PMQ`), \
             found `FOO`"
        );
        assert_eq!(
            error(&format!("{base}PostOffice:\n")),
            "dcdt.cfg:2:12: expected a PostOffice policy (`SLWB`, `SLWDWCV`, `SLWSM` or `PMQ`), \
             found end of line"
        );
        assert_eq!(
            error(&format!("{base}PostOffice: SLWB SLWSM\n")),
            "dcdt.cfg:2:18: expected end of line after the PostOffice policy, found `SLWSM`"
        );
        assert_eq!(
            error(&format!("{base}PostOffice: SLWB\n\n  PostOffice: PMQ\n")),
            "dcdt.cfg:4:3: expected at most one `PostOffice:` line, found a second one \
             (the first is on line 2)"
        );
        assert_eq!(
            error(&format!("{base}PostOffice : SLWB\n")),
            "dcdt.cfg:2:1: expected `ip`, `ser` or `PostOffice:`, found `PostOffice`"
        );
    }

    #[test]
    fn channel_line_errors() {
        let base = "1.2.3.4 225.0.0.1 2003\n";
        let cases = [
            ("ip", "2:3: expected `link` or `bridge`, found end of line"),
            ("ip link -1", "2:9: expected a level (an integer 0-4294967295), found `-1`"),
            (
                "ip link 4294967296",
                "2:9: expected a level (an integer 0-4294967295), found `4294967296`",
            ),
            ("ip link 0", "2:10: expected a local IP address, found end of line"),
            ("ip link 0 1.2.3", "2:11: expected a local IP address, found `1.2.3`"),
            ("ip link 0 1.2.3.4 0", "2:19: expected a local port (1-65535), found `0`"),
            ("ip link 0 1.2.3.4 1 x", "2:21: expected a remote IP address, found `x`"),
            (
                "ip link 0 1.2.3.4 1 ::1",
                "2:24: expected a remote port (1-65535), found end of line",
            ),
            (
                "ip link 0 1.2.3.4 1 ::1 65536",
                "2:25: expected a remote port (1-65535), found `65536`",
            ),
            (
                "ip link 0 1.2.3.4 1 ::1 2 3",
                "2:27: expected end of line after the remote port, found `3`",
            ),
            (
                "ser bridge 2",
                "2:13: expected a serial device path such as `/dev/ttyS0`, found end of line",
            ),
            (
                "ser bridge 2 /dev/ttyS0 9600",
                "2:25: expected end of line after the device, found `9600`",
            ),
            ("IP link 0 1.2.3.4 1 ::1 2", "2:1: expected `ip`, `ser` or `PostOffice:`, found `IP`"),
            ("ser Link 0 /dev/ttyS0", "2:5: expected `link` or `bridge`, found `Link`"),
        ];
        for (line, expected) in cases {
            assert_eq!(error(&format!("{base}{line}\n")), format!("dcdt.cfg:{expected}"), "{line}");
        }
    }

    #[test]
    fn found_tokens_are_escaped_and_shortened() {
        let long = "x".repeat(100);
        let message = error(&format!("1.2.3.4 225.0.0.1 2003\n{long}\n"));
        assert!(message.ends_with(&format!("found `{}…`", "x".repeat(40))), "{message}");
        let message = error("1.2.3.4 225.0.0.1 20\u{1b}03\n");
        assert!(message.ends_with("found `20\\u{1b}03`"), "{message}");
    }

    #[test]
    fn comments_tabs_crlf_and_blank_lines() {
        let text = "# header comment\r\n\
                    \r\n\
                    \t 192.168.0.1\t225.0.0.1 2003 # trailing comment\r\n\
                    \t\t\r\n\
                    PostOffice:\tSLWB#glued comment\r\n\
                    ip\tlink 0 192.168.0.1 3000 192.168.1.1 3000 \t\r\n\
                    # final comment without newline";
        let config = parse(text);
        assert_eq!(config, parse(MANUAL_EXAMPLE));
        assert_eq!(
            error("1.2.3.4 225.0.0.1\r\n"),
            "dcdt.cfg:1:18: expected a port (1-65535), found end of line"
        );
        // A stray carriage return separates tokens.
        let config = parse("1.2.3.4\r225.0.0.1 2003\nser link 0 /dev/ttyS0\r\r\n");
        assert_eq!(
            config.channels[0],
            Channel::Serial { mode: ChannelMode::Link, level: 0, device: "/dev/ttyS0".into() }
        );
        // A comment-only line at any place, and a `#` glued to a token.
        let config = parse("1.2.3.4 225.0.0.1 2003#c\n#ip link 0\nser link 0 /dev/ttyUSB0#c\n");
        assert_eq!(
            config.channels,
            vec![Channel::Serial {
                mode: ChannelMode::Link,
                level: 0,
                device: "/dev/ttyUSB0".into()
            }]
        );
        // Columns count characters, not bytes, and a leading BOM is skipped.
        assert_eq!(
            error("\u{feff}1.2.3.4 225.0.0.1 2003\n# é\nser link é\n"),
            "dcdt.cfg:3:10: expected a level (an integer 0-4294967295), found `é`"
        );
    }

    #[test]
    fn ipv6_serial_bridge_and_order() {
        let text = "fe80::1 ff02::1:2 4000\n\
                    ser bridge 3 /dev/ttyS1\n\
                    ip bridge 7 ::1 1 2001:db8::2 65535\n\
                    ser link 0 COM3\n\
                    ip link 1 10.0.0.1 3000 10.0.0.2 3001\n";
        let config = parse(text);
        assert_eq!(config.local_ip, ip("fe80::1"));
        assert_eq!(config.multicast, IpAddr::V6(Ipv6Addr::new(0xff02, 0, 0, 0, 0, 0, 1, 2)));
        assert_eq!(config.port, 4000);
        assert_eq!(config.policy, None);
        assert_eq!(
            config.channels,
            vec![
                Channel::Serial {
                    mode: ChannelMode::Bridge,
                    level: 3,
                    device: "/dev/ttyS1".into()
                },
                Channel::Ip {
                    mode: ChannelMode::Bridge,
                    level: 7,
                    local_addr: ip("::1"),
                    local_port: 1,
                    remote_addr: ip("2001:db8::2"),
                    remote_port: 65535,
                },
                Channel::Serial { mode: ChannelMode::Link, level: 0, device: "COM3".into() },
                Channel::Ip {
                    mode: ChannelMode::Link,
                    level: 1,
                    local_addr: ip("10.0.0.1"),
                    local_port: 3000,
                    remote_addr: ip("10.0.0.2"),
                    remote_port: 3001,
                },
            ]
        );
        assert_eq!(config.to_string(), text);
    }

    #[test]
    fn invalid_utf8_is_reported_at_the_first_bad_byte() {
        let bytes = b"1.2.3.4 225.0.0.1 2003\nser link 0 /dev/tty\xc3\xa9\xff\n";
        let message = match AgoraConfig::parse_bytes(bytes, "dcdt.cfg") {
            Ok(config) => panic!("parsed {config:?}"),
            Err(error) => error.to_string(),
        };
        assert_eq!(message, "dcdt.cfg:2:21: expected UTF-8 text, found the invalid byte 0xFF");
        let config = AgoraConfig::parse_bytes(MANUAL_EXAMPLE.as_bytes(), "dcdt.cfg");
        assert_eq!(config.ok(), Some(parse(MANUAL_EXAMPLE)));
    }

    #[test]
    fn from_file_reads_and_reports_io_errors() {
        let path =
            std::env::temp_dir().join(format!("mrt-dcdt-config-test-{}.cfg", std::process::id()));
        if let Err(error) = std::fs::write(&path, MANUAL_EXAMPLE) {
            panic!("cannot write {}: {error}", path.display());
        }
        let config = AgoraConfig::from_file(&path);
        let _ = std::fs::remove_file(&path);
        assert_eq!(config.ok(), Some(parse(MANUAL_EXAMPLE)));

        match AgoraConfig::from_file("/nonexistent/dcdt.cfg") {
            Err(error @ ConfigError::Io { .. }) => {
                assert!(error.to_string().starts_with("/nonexistent/dcdt.cfg: "), "{error}");
                assert!(std::error::Error::source(&error).is_some());
            }
            other => panic!("expected an I/O error, got {other:?}"),
        }
    }

    #[test]
    fn policy_names() {
        for kind in PolicyKind::ALL {
            assert_eq!(kind.name().parse::<PolicyKind>(), Ok(kind));
            assert_eq!(kind.to_string(), kind.name());
            assert!(KNOWN_POLICIES.contains(&format!("`{}`", kind.name())));
        }
        assert_eq!(PolicyKind::default(), PolicyKind::Pmq);
        let unknown = "Slwb".parse::<PolicyKind>();
        assert_eq!(unknown, Err(UnknownPolicy("Slwb".into())));
        assert_eq!(
            unknown.map_err(|e| e.to_string()),
            Err("unknown PostOffice policy `Slwb`, expected `SLWB`, `SLWDWCV`, `SLWSM` or `PMQ`"
                .into())
        );
    }

    #[test]
    fn sample_files_parse() {
        let lan = parse(include_str!("../../../configs/dcdt/standalone_lan.cfg"));
        assert_eq!(lan.policy, Some(PolicyKind::Pmq));
        assert!(lan.channels.is_empty());

        let link = parse(include_str!("../../../configs/dcdt/static_link.cfg"));
        assert_eq!(link, parse(MANUAL_EXAMPLE));

        let gateway = parse(include_str!("../../../configs/dcdt/bridge_and_serial.cfg"));
        assert_eq!(gateway.policy, Some(PolicyKind::Slwdwcv));
        assert!(matches!(
            gateway.channels.as_slice(),
            [
                Channel::Ip { mode: ChannelMode::Bridge, .. },
                Channel::Serial { mode: ChannelMode::Link, .. }
            ]
        ));
    }

    fn any_ip() -> impl Strategy<Value = IpAddr> {
        prop_oneof![any::<Ipv4Addr>().prop_map(IpAddr::V4), any::<Ipv6Addr>().prop_map(IpAddr::V6),]
    }

    fn multicast_ip() -> impl Strategy<Value = IpAddr> {
        prop_oneof![
            (224u8..=239, any::<[u8; 3]>())
                .prop_map(|(a, [b, c, d])| IpAddr::V4(Ipv4Addr::new(a, b, c, d))),
            any::<[u8; 15]>().prop_map(|rest| {
                let mut octets = [0xff; 16];
                octets[1..].copy_from_slice(&rest);
                IpAddr::V6(Ipv6Addr::from(octets))
            }),
        ]
    }

    fn mode() -> impl Strategy<Value = ChannelMode> {
        prop_oneof![Just(ChannelMode::Link), Just(ChannelMode::Bridge)]
    }

    fn channel() -> impl Strategy<Value = Channel> {
        prop_oneof![
            (mode(), any::<u32>(), any_ip(), 1..=u16::MAX, any_ip(), 1..=u16::MAX).prop_map(
                |(mode, level, local_addr, local_port, remote_addr, remote_port)| Channel::Ip {
                    mode,
                    level,
                    local_addr,
                    local_port,
                    remote_addr,
                    remote_port,
                }
            ),
            (mode(), any::<u32>(), "[^ \t#\r\n]{1,12}")
                .prop_map(|(mode, level, device)| { Channel::Serial { mode, level, device } }),
        ]
    }

    fn config() -> impl Strategy<Value = AgoraConfig> {
        (
            any_ip(),
            multicast_ip(),
            1..=u16::MAX,
            proptest::option::of(proptest::sample::select(PolicyKind::ALL.to_vec())),
            proptest::collection::vec(channel(), 0..8),
        )
            .prop_map(|(local_ip, multicast, port, policy, channels)| AgoraConfig {
                local_ip,
                multicast,
                port,
                policy,
                channels,
            })
    }

    const ALPHABET: &[&str] = &[
        "ip",
        "ser",
        "link",
        "bridge",
        "PostOffice:",
        "PostOffice",
        "SLWB",
        "SLWDWCV",
        "SLWSM",
        "PMQ",
        "0",
        "1",
        "3000",
        "65535",
        "65536",
        "99999",
        "4294967296",
        "-1",
        "192.168.0.1",
        "225.0.0.1",
        "ff02::1",
        "::1",
        "fe80::1%eth0",
        "/dev/ttyS0",
        "#",
        " ",
        "\t",
        "\n",
        "\r\n",
        "\r",
        "\u{feff}",
        "é",
        "💥",
        "`",
        "\0",
        "foo",
    ];

    /// Random tokens, half of the time after a valid network line so that
    /// the channel and PostOffice parsers are reached too.
    fn token_soup() -> impl Strategy<Value = String> {
        let start = prop_oneof![Just(""), Just("1.2.3.4 225.0.0.1 2003\n")];
        let tokens = proptest::collection::vec(
            prop_oneof![
                4 => proptest::sample::select(ALPHABET).prop_map(String::from),
                3 => proptest::sample::select(&[" ", "\t", "\n"][..]).prop_map(String::from),
                1 => ".{0,4}",
            ],
            0..60,
        );
        (start, tokens).prop_map(|(start, tokens)| format!("{start}{}", tokens.concat()))
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
            let _ = AgoraConfig::parse_bytes(&bytes, "fuzz.cfg");
        }

        #[test]
        fn token_soup_never_panics(text in token_soup()) {
            match AgoraConfig::parse(&text, "fuzz.cfg") {
                // Whatever parses is printed back to something that parses the same.
                Ok(config) => prop_assert_eq!(AgoraConfig::parse(&config.to_string(), "x").ok(), Some(config)),
                Err(ConfigError::Parse { line, column, .. }) => prop_assert!(line >= 1 && column >= 1),
                Err(error) => prop_assert!(false, "unexpected error {error:?}"),
            }
        }

        #[test]
        fn valid_configs_round_trip(config in config()) {
            let text = config.to_string();
            match AgoraConfig::parse(&text, "roundtrip.cfg") {
                Ok(parsed) => prop_assert_eq!(parsed, config),
                Err(error) => prop_assert!(false, "{error}\n{text}"),
            }
        }
    }
}
