"""The validation report (`bearing-twin report`, report.py) and its sections: EHL (ehl.py), EV
motor bearing under shaft current (ev.py), angular-contact 7208 family against Jones
(angular_contact.py). Offline: on top of the service layers (import-linter contract "layers")."""
