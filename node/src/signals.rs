//! Ending loops cleanly on SIGINT and SIGTERM, so that files get finished.

/// SIGINT and SIGTERM set the returned flag, so loops can end cleanly (and files get finished).
pub fn shutdown_flag() -> anyhow::Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, flag.clone())?;
    }
    Ok(flag)
}
