"""A relaxing sample's one answer (``palpate.campaigns.pooled``): its relaxed modulus, judged
on its trials' relaxed verdicts and on how many relaxed records contradict a stated belief."""

from __future__ import annotations

from palpate.campaigns.pooled import CONTRADICTING, pooled_sample
from palpate.estimation.jointfit import JointFit
from palpate.estimation.jointfit.beliefcheck import CONTRADICTED
from palpate.estimation.jointfit.pooling import Terms
from palpate.estimation.relaxation import RelaxationFit
from palpate.estimation.verdict import Verdict
from palpate.robot.trial.outcome import Outcome

ALARM = f"{CONTRADICTED} belief: the relaxed record prefers a 10 mm layer to the stated 20 mm: 40"


def trial(relaxed: float, alarm: bool = False) -> Outcome:
    """A held trial that relaxes: an apparent elastic number, the relaxed one +-5 %."""
    joint = JointFit(True, "ok", modulus=1.1 * relaxed, terms=Terms(1.1 * relaxed, 0.01))
    warnings = (ALARM,) if alarm else ()
    fit = RelaxationFit(
        True, "ok", relaxed, 0.95 * relaxed, 1.05 * relaxed, relaxes=True, warnings=warnings
    )
    relaxed_verdict = Verdict("suspect", (ALARM,)) if alarm else Verdict("ok")
    return Outcome(
        state="done",
        reason="completed",
        joint=joint,
        verdict=Verdict("suspect", ("relaxes in the hold",)),
        relaxation=fit,
        relaxed_verdict=relaxed_verdict,
    )


def test_a_relaxing_sample_answers_with_the_median_relaxed_modulus() -> None:
    p = pooled_sample([trial(1.0e3), trial(1.1e3), trial(1.2e3)])
    assert p.modulus == "relaxed"
    assert p.status == "ok"
    assert p.fit.modulus == 1.1e3


def test_one_contradicting_trial_is_not_the_samples_alarm_two_are() -> None:
    one = [trial(1.0e3, alarm=True), *(trial(1.0e3) for _ in range(8))]
    assert pooled_sample(one).status == "ok"
    two = [trial(1.0e3, alarm=True) for _ in range(CONTRADICTING)] + [trial(1.0e3)] * 7
    sample = pooled_sample(two)
    assert sample.status == "suspect"
    assert sample.reasons[0].startswith(f"{CONTRADICTING} of 9 relaxed records say: {CONTRADICTED}")
