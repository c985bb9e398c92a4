//! The peers a user would run instead, at the same size: MeshLab's screened Poisson + QEM,
//! Instant Meshes and QuadriFlow (each fitted as a Catmull-Clark cage by least squares), made
//! by `tools/peers/peers.py` into a folder with a `peers.json`, judged here by the same judge
//! as our cages.

use std::path::Path;

use serde::Deserialize;

use crate::inputs::scheme_named;
use crate::judge::JudgeOptions;
use crate::row::{Judged, Row};
use crate::score::judge_peer;

/// One result of `peers.json`.
#[derive(Clone, Debug, Deserialize)]
pub struct PeerResult {
    /// The corpus entry.
    pub entry: String,
    /// `poisson-qem`, `instant-meshes`, `quadriflow`.
    pub peer: String,
    /// `mesh` (judged as its triangles) or `limit` (a cage judged by its limit surface).
    pub kind: String,
    /// The cage's scheme (`catmull-clark`), for `limit`.
    pub scheme: Option<String>,
    /// The output file, relative to the peers folder.
    pub file: Option<String>,
    /// Wall time to make it, seconds.
    pub seconds: Option<f64>,
    /// Why it failed.
    pub error: Option<String>,
}

#[derive(Deserialize)]
struct PeersFile {
    peers: Vec<PeerResult>,
}

/// Reads `dir/peers.json`. Errors: unreadable or malformed, with the path.
pub fn read_peers(dir: &Path) -> Result<Vec<PeerResult>, String> {
    let path = dir.join("peers.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let f: PeersFile =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(f.peers)
}

/// Judges the peers of each row (by entry name) and adds them to the row.
pub fn add_peers(rows: &mut [Row], peers: &[PeerResult], dir: &Path, options: &JudgeOptions) {
    for row in rows.iter_mut() {
        for p in peers.iter().filter(|p| p.entry == row.entry) {
            let judged = match (&p.error, &p.file) {
                (None, Some(file)) => judge_peer(
                    Path::new(&row.input),
                    &p.peer,
                    &dir.join(file),
                    &p.kind,
                    p.scheme.as_deref().and_then(scheme_named),
                    p.seconds,
                    options,
                ),
                (error, _) => Judged {
                    by: p.peer.clone(),
                    stats: Default::default(),
                    judge: None,
                    seconds: p.seconds,
                    error: Some(error.clone().unwrap_or_else(|| "no output file".into())),
                },
            };
            row.peers.push(judged);
        }
    }
}
