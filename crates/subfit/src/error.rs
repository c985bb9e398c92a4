//! Why [`crate::fit_scan`] failed (STYLE.md rule 5): each variant names the input and what is
//! wrong with it, so that a front end prints one line and exits.

/// Why the pipeline failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An option is invalid or options contradict each other (nothing was read).
    #[error("{0}")]
    Options(String),
    /// A file could not be read or written.
    #[error(transparent)]
    Io(#[from] subfit_io::Error),
    /// The target cannot be used (the message names the file and the element).
    #[error("{name}: {message}")]
    Input {
        /// The input's name (its file).
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A budget the user gave cannot be honoured (e.g. the initial cage already has more
    /// control points).
    #[error("{0}")]
    Budget(String),
    /// Building the initial control mesh failed.
    #[error("{name}: cannot build an initial control mesh: {source}")]
    Init {
        /// The input's name.
        name: String,
        /// The cause.
        source: subfit_init::InitError,
    },
    /// Fitting failed.
    #[error("{name}: fitting failed: {source}")]
    Fit {
        /// The input's name.
        name: String,
        /// The cause.
        source: subfit_fit::FitError,
    },
    /// The run was cancelled through [`crate::FitScanOptions::cancel`].
    #[error("interrupted")]
    Interrupted,
    /// The outputs could not be built.
    #[error("cannot build the outputs: {0}")]
    Output(String),
}

impl Error {
    pub(crate) fn input(name: &str, message: impl std::fmt::Display) -> Self {
        Self::Input {
            name: name.to_string(),
            message: message.to_string(),
        }
    }

    /// The target named `name` cannot be analysed: [`Self::Interrupted`] when the run was
    /// cancelled, else [`Self::Input`] with the reason and, for too few points, a hint at the
    /// usual mistake (a scan needs thousands of points: a file of tens is a cage, a set of
    /// landmarks or the wrong file).
    pub(crate) fn target(name: &str, e: subfit_target::TargetError) -> Self {
        use subfit_target::TargetError as T;
        match e {
            T::Interrupted => Self::Interrupted,
            T::TooFewPoints { .. } | T::TooFewDistinctPoints { .. } => Self::input(
                name,
                format!(
                    "{e}; hint: a scan to fit has thousands of points — is this a control \
                     mesh or a set of landmarks? (a cage to start from goes to --init)"
                ),
            ),
            e => Self::input(name, e),
        }
    }
}
