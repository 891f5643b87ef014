"""A built dataset's products: manifest, card, gallery, contact sheets, shards, collation, diversity and the check."""
