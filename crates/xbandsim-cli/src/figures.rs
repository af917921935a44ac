pub fn run(_o: &std::path::Path, _s: &std::path::Path, _seed: u64) -> anyhow::Result<()> {
    Ok(())
}
