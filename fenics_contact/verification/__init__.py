"""Problems with known answers: analytic references and benchmark problems, each defined once."""
