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
    /// `mesh` (judged as its triangles) or `limit` (a cage judged by its limit surface); null
    /// for a peer that failed.
    pub kind: Option<String>,
    /// The cage's scheme (`catmull-clark`), for `limit`.
    pub scheme: Option<String>,
    /// The output file, relative to the peers folder.
    pub file: Option<String>,
    /// Wall time to make it, seconds.
    pub seconds: Option<f64>,
    /// Why it failed.
    pub error: Option<String>,
    /// The vertex count it was made for (our cage's when peers.py ran).
    #[serde(default)]
    pub target_vertices: Option<usize>,
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
        let ours = row.cage.as_ref().map(|c| c.control_points);
        for p in peers.iter().filter(|p| p.entry == row.entry) {
            // A peer made for another size than our cage is not the same-size comparison.
            let stale = match (p.target_vertices, ours) {
                (Some(t), Some(o)) if t != o => Some(format!(
                    "made for {t} vertices, our cage has {o}: run tools/peers again"
                )),
                _ => None,
            };
            let judged = match (&p.error, &p.file, stale) {
                (None, Some(_), None) if p.kind.is_none() => Judged {
                    by: p.peer.clone(),
                    stats: Default::default(),
                    judge: None,
                    seconds: p.seconds,
                    error: Some("peers.json gives no kind".into()),
                },
                (_, _, Some(stale)) => Judged {
                    by: p.peer.clone(),
                    stats: Default::default(),
                    judge: None,
                    seconds: None,
                    error: Some(stale),
                },
                (None, Some(file), None) => judge_peer(
                    Path::new(&row.input),
                    &p.peer,
                    &dir.join(file),
                    p.kind.as_deref().unwrap_or_default(),
                    p.scheme.as_deref().and_then(scheme_named),
                    p.seconds,
                    options,
                ),
                (error, _, None) => Judged {
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
